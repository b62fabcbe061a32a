// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Step 3 of adaptive sampling, classification of the pieces between the
// borders of two samples, the first visible one shaded; intervals where a
// border could hide are refined first (vtkVolumeCutPieceClassifier.h).
// Replaces the skeleton's VolumeCut::PieceClassification::Dec tag.

uniform int refinements;

// The borders between two samples and the first visible piece between them.
bool leafInterval(inout Sample a, inout Sample b)
{
  // A border exactly at the previous sample: enter the material that starts at a.
  if (!insideVisible && visible(a))
  {
    if (enter(a, a.t, SOURCE_OBJECT))
    {
      return true;
    }
    insideVisible = true;
  }
  float borderT[CUT_SLOTS + 1];
  int borderSource[CUT_SLOTS + 1];
  int count = 0;
  if (a.object != b.object)
  {
    borderT[count] = bisectObject(a, b);
    borderSource[count] = SOURCE_OBJECT;
    ++count;
  }
  if (a.cutsKnown && b.cutsKnown)
  {
    for (int n = 0; n < NUMBER_OF_CUTS; ++n)
    {
      if ((a.distance[n] < 0.0) != (b.distance[n] < 0.0))
      {
        borderT[count] = bisectCut(n, a, b);
        borderSource[count] = SOURCE_CUT + n;
        ++count;
      }
    }
  }
  sortBorders(borderT, borderSource, count);
  for (int border = 0; border < count; ++border)
  {
    float endT = border + 1 < count ? borderT[border + 1] : b.t;
    Sample mid = sampleAt(0.5 * (borderT[border] + endT));
    evaluateObject(mid);
    bool isVisible = visible(mid);
    if (isVisible && !insideVisible && enter(mid, borderT[border], borderSource[border]))
    {
      return true;
    }
    insideVisible = isVisible;
  }
  return false;
}

bool surfaceInterval(inout Sample a, inout Sample b, float voxelsPerMillimetre)
{
  if (a.object != 0 || b.object != 0)
  {
    evaluateCuts(a);
    evaluateCuts(b);
  }
  if (mayHideBorders(a, b, (b.t - a.t) * voxelsPerMillimetre, b.t - a.t))
  {
    int parts = 1 << refinements;
    Sample from = a;
    for (int part = 1; part <= parts; ++part)
    {
      Sample to = part == parts ? b : sampleAt(a.t + (b.t - a.t) * float(part) / float(parts));
      if (part < parts)
      {
        evaluateObject(to);
      }
      if (from.object != 0 || to.object != 0)
      {
        evaluateCuts(from);
        evaluateCuts(to);
      }
      if (leafInterval(from, to))
      {
        return true;
      }
      from = to;
    }
    return false;
  }
  return leafInterval(a, b);
}
