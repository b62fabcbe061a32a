// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Step 1 for the cut fields: each field's signed distance at a sample
// (removed where negative). The composer writes one copy of
// vtkVolumeCutCutFieldFS.glsl per field and the dispatch by
// field index below. Replaces the skeleton's
// VolumeCut::CutFields::Dec tag.

//VolumeCut::CutField::Dec

float cutDistance(int n, vec3 world)
{
  //VolumeCut::CutField::Calls
  return 1.0;
}

void evaluateCuts(inout Sample s)
{
  if (s.cutsKnown)
  {
    return;
  }
  vec3 world = worldPoint(s.index);
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    s.distance[n] = cutDistance(n, world);
  }
  s.cutsKnown = true;
}

bool removed(Sample s)
{
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    if (s.distance[n] < 0.0)
    {
      return true;
    }
  }
  return false;
}

// Where a sample's removed depth ends: the cut fields are distances (1 mm
// per mm), so no field's border lies nearer along the ray than this.
float removedDepthExit(Sample s)
{
  float exitT = s.t;
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    exitT = max(exitT, s.t - s.distance[n]);
  }
  return exitT;
}

bool visible(inout Sample s)
{
  if (s.object == 0)
  {
    return false;
  }
  evaluateCuts(s);
  return !removed(s);
}
