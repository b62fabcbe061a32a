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

uniform int exactHiddenBorders;  // settle the gradient bound with reaches()
uniform int intervalPieces;      // at most this many cell pieces in reaches()

// Whether the trilinear CT reaches level somewhere on the segment from p to
// q (IJK) (vtkVolumeCutSampleClassifier::Reaches): in each cell the segment
// crosses, the value along it is a cubic in the segment's parameter, whose
// maximum lies at an end of the piece or where its derivative vanishes. The
// cells are walked in order, so no array holds the pieces.
bool reaches(vec3 p, vec3 q, float level)
{
  vec3 d = q - p;
  ivec3 wallStep = ivec3(sign(d));
  // The next cell wall the segment crosses along each axis (an integer
  // strictly beyond p), and its parameter; 2.0 (past the end) where none.
  vec3 wall = vec3(0.0);
  vec3 tWall = vec3(2.0);
  for (int axis = 0; axis < 3; ++axis)
  {
    if (abs(d[axis]) >= 1e-12)
    {
      wall[axis] = d[axis] > 0.0 ? floor(p[axis]) + 1.0 : ceil(p[axis]) - 1.0;
      tWall[axis] = (wall[axis] - p[axis]) / d[axis];
    }
  }
  float t0 = 0.0;
  for (int piece = 0; piece < intervalPieces; ++piece)
  {
    float t1 = min(min(min(tWall.x, tWall.y), tWall.z), 1.0);
    if (t1 > t0)
    {
      ivec3 base;
      vec3 f;
      cellOf(p + 0.5 * (t0 + t1) * d, base, f);
      CellValues c = cellValuesAt(base);
      float highest = max(max(max(c.v000, c.v100), max(c.v010, c.v110)), max(max(c.v001, c.v101), max(c.v011, c.v111)));
      float largest = max(highest, -min(min(min(c.v000, c.v100), min(c.v010, c.v110)), min(min(c.v001, c.v101), min(c.v011, c.v111))));
      // Float arithmetic errs by about 1e-6 of the values' size: the margin,
      // ten times that, errs towards a refined interval, never a missed one.
      float margin = 1e-5 * (abs(level) + largest) + 1e-6;
      if (highest + margin >= level)
      {
        // Trilinear value as A + Bx + Cy + Dz + Exy + Fxz + Gyz + Hxyz.
        float B = c.v100 - c.v000;
        float C = c.v010 - c.v000;
        float D = c.v001 - c.v000;
        float E = c.v110 - c.v010 - c.v100 + c.v000;
        float F = c.v101 - c.v001 - c.v100 + c.v000;
        float G = c.v011 - c.v001 - c.v010 + c.v000;
        float H = c.v111 - c.v011 - c.v101 - c.v110 + c.v001 + c.v010 + c.v100 - c.v000;
        vec3 o = p - vec3(base);
        float k0 = c.v000 + B * o.x + C * o.y + D * o.z + E * o.x * o.y + F * o.x * o.z + G * o.y * o.z + H * o.x * o.y * o.z;
        float k1 = B * d.x + C * d.y + D * d.z + E * (o.x * d.y + o.y * d.x) + F * (o.x * d.z + o.z * d.x) +
          G * (o.y * d.z + o.z * d.y) + H * (d.x * o.y * o.z + o.x * d.y * o.z + o.x * o.y * d.z);
        float k2 = E * d.x * d.y + F * d.x * d.z + G * d.y * d.z + H * (d.x * d.y * o.z + d.x * o.y * d.z + o.x * d.y * d.z);
        float k3 = H * d.x * d.y * d.z;
        if (k0 + t0 * (k1 + t0 * (k2 + t0 * k3)) + margin >= level || k0 + t1 * (k1 + t1 * (k2 + t1 * k3)) + margin >= level)
        {
          return true;
        }
        // Stationary points: roots of k1 + 2 k2 t + 3 k3 t^2.
        float a2 = 3.0 * k3;
        float a1 = 2.0 * k2;
        float root0 = 2.0;
        float root1 = 2.0;
        if (abs(a2) > 1e-30)
        {
          float discriminant = a1 * a1 - 4.0 * a2 * k1;
          if (discriminant >= 0.0)
          {
            float root = sqrt(discriminant);
            root0 = (-a1 - root) / (2.0 * a2);
            root1 = (-a1 + root) / (2.0 * a2);
          }
        }
        else if (abs(a1) > 1e-30)
        {
          root0 = -k1 / a1;
        }
        if ((root0 > t0 && root0 < t1 && k0 + root0 * (k1 + root0 * (k2 + root0 * k3)) + margin >= level) ||
          (root1 > t0 && root1 < t1 && k0 + root1 * (k1 + root1 * (k2 + root1 * k3)) + margin >= level))
        {
          return true;
        }
      }
    }
    if (t1 >= 1.0)
    {
      return false;
    }
    // Past the wall (or walls, at an edge or corner) at t1.
    for (int axis = 0; axis < 3; ++axis)
    {
      if (tWall[axis] <= t1)
      {
        wall[axis] += float(wallStep[axis]);
        tWall[axis] = (wall[axis] - p[axis]) / d[axis];
      }
    }
    t0 = t1;
  }
  // More pieces than the bound: as if the CT reached the level.
  return true;
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
    if (0.5 * (a.value + b.value + slope * lengthVoxels) < minimumIso)
    {
      return false;
    }
    // The block's gradient bound is loose beside bone, where it would have
    // every step split; the exact maximum along the interval settles those.
    return exactHiddenBorders == 0 || reaches(a.index, b.index, minimumIso);
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
