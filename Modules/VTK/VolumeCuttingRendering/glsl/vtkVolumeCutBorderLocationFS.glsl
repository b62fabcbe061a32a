// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Step 2 of adaptive sampling, border location: bisection on the object
// class and on each cut field's distance between two samples, the volume's
// box and the clip planes analytically, and the Lipschitz bounds that say
// where a border could hide between samples (vtkVolumeCutBorderLocator.h).
// Replaces the skeleton's VolumeCut::BorderLocation::Dec tag.

uniform int planeCount;
uniform vec4 planes[6];
// Halvings of a bisection (22: 2^-22 of a step). A uniform, not a constant:
// a constant bound lets drivers unroll the loop, and with it every sample
// evaluation inside, into minutes of compilation.
uniform int bisectionSteps;

// Entry and exit of the ray (tStart, tEnd: its near and far limits before):
// the volume's box, the sample domain, then the clip planes; entryNormal
// becomes the entry surface's. False when the ray misses.
bool clipToVolume(inout float tStart, inout float tEnd)
{
  for (int axis = 0; axis < 3; ++axis)
  {
    float lo = 0.0;
    float hi = float(dimensions[axis] - 1);
    if (abs(rayDirection[axis]) < 1e-15)
    {
      if (rayOrigin[axis] < lo || rayOrigin[axis] > hi)
      {
        return false;
      }
      continue;
    }
    float t0 = (lo - rayOrigin[axis]) / rayDirection[axis];
    float t1 = (hi - rayOrigin[axis]) / rayDirection[axis];
    bool forward = t0 < t1;
    if (!forward)
    {
      float swap = t0;
      t0 = t1;
      t1 = swap;
    }
    if (t0 > tStart)
    {
      tStart = t0;
      vec3 face = vec3(0.0);
      face[axis] = forward ? -1.0 : 1.0;
      entryNormal = normalize(normalMatrix * face);
    }
    tEnd = min(tEnd, t1);
  }
  for (int p = 0; p < planeCount; ++p)
  {
    float f0 = dot(planes[p].xyz, originWorld) + planes[p].w;
    float fd = dot(planes[p].xyz, directionWorld);
    if (abs(fd) < 1e-15)
    {
      if (f0 < 0.0)
      {
        return false;
      }
      continue;
    }
    float t = -f0 / fd;
    if (fd > 0.0)
    {
      if (t > tStart)
      {
        tStart = t;
        entryNormal = -normalize(planes[p].xyz);
      }
    }
    else
    {
      tEnd = min(tEnd, t);
    }
  }
  return tStart < tEnd;
}

float bisectObject(Sample a, Sample b)
{
  float lo = a.t;
  float hi = b.t;
  for (int iteration = 0; iteration < bisectionSteps; ++iteration)
  {
    Sample mid = sampleAt(0.5 * (lo + hi));
    evaluateObject(mid);
    if (mid.object == a.object)
    {
      lo = mid.t;
    }
    else
    {
      hi = mid.t;
    }
  }
  return 0.5 * (lo + hi);
}

float bisectCut(int n, Sample a, Sample b)
{
  float lo = a.t;
  float hi = b.t;
  bool loRemoved = a.distance[n] < 0.0;
  for (int iteration = 0; iteration < bisectionSteps; ++iteration)
  {
    float t = 0.5 * (lo + hi);
    if ((cutDistance(n, worldPoint(rayOrigin + t * rayDirection)) < 0.0) == loRemoved)
    {
      lo = t;
    }
    else
    {
      hi = t;
    }
  }
  return 0.5 * (lo + hi);
}

bool mayHideBorders(Sample a, Sample b, float lengthVoxels, float lengthMillimetres)
{
  if (a.object == 0 && b.object == 0)
  {
    if (anyIso == 0)
    {
      return false;
    }
    float slope = max(texelFetch(blockTexture, blockOf(a.index), 0).g, texelFetch(blockTexture, blockOf(b.index), 0).g);
    return 0.5 * (a.value + b.value + slope * lengthVoxels) >= minimumIso;
  }
  if (!a.cutsKnown || !b.cutsKnown)
  {
    return false;
  }
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    float da = a.distance[n];
    float db = b.distance[n];
    if ((da >= 0.0) == (db >= 0.0) && abs(da) + abs(db) < lengthMillimetres)
    {
      return true;
    }
  }
  return false;
}

// Insertion sort of at most NUMBER_OF_CUTS + 1 borders by ray parameter.
void sortBorders(inout float borderT[CUT_SLOTS + 1], inout int borderSource[CUT_SLOTS + 1], int count)
{
  for (int i = 1; i < count; ++i)
  {
    for (int j = i; j > 0 && borderT[j - 1] > borderT[j]; --j)
    {
      float t = borderT[j];
      borderT[j] = borderT[j - 1];
      borderT[j - 1] = t;
      int source = borderSource[j];
      borderSource[j] = borderSource[j - 1];
      borderSource[j - 1] = source;
    }
  }
}
