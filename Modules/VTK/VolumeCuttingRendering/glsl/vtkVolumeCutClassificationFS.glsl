// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Step 1 of adaptive sampling, classification at a sample point: which
// segment's object is there and the CT value (vtkVolumeCutSampleClassifier.h
// documents it). Replaces the skeleton's VolumeCut::Classification::Dec tag.

uniform sampler3D anatomyTexture;   // CT: R32F, or R16 (ANATOMY_UNORM16), GL_LINEAR if ANATOMY_FILTERED
uniform float anatomyMinimum;       // R16: the CT value of texel 0
uniform sampler3D labelTexture;     // labels, when hasLabels: R16 or R8, unsigned normalized
uniform float labelScale;           // 65535 (R16) or 255 (R8)
uniform sampler2D styleTexture;     // per label: (rgb, opacity), (iso, shape, 0, 0), (uncut surface rgb, 0)
uniform int hasLabels;             // a label map or fractional labelmaps
uniform int hasLabelMap;
uniform sampler3D fractionTexture;  // up to 4 segments' fractions (RGBA), GL_LINEAR if FRACTIONS_FILTERED
uniform int fractionCount;
uniform vec4 fractionLabels;
uniform int styleCount;
uniform int anyIso;
uniform float minimumIso;

// The CT value of voxel i, as the CPU holds it. A 16-bit texel stores
// value - anatomyMinimum, an integer k as k / 65535: rounding 65535 * texel
// gives k back exactly (the conversion errs far less than 0.5), so the sum is
// the float the CPU has, bit for bit (the caster uploads R16 only then).
float anatomyAt(ivec3 i)
{
#ifdef ANATOMY_UNORM16
  return anatomyMinimum + round(65535.0 * texelFetch(anatomyTexture, i, 0).r);
#else
  return texelFetch(anatomyTexture, i, 0).r;
#endif
}

// The label of voxel i (exact for the same reason).
int labelAt(ivec3 i) { return int(labelScale * texelFetch(labelTexture, i, 0).r + 0.5); }

void cellOf(vec3 p, out ivec3 base, out vec3 f)
{
  vec3 x = clamp(p, vec3(0.0), vec3(dimensions - 1));
  base = min(ivec3(x), dimensions - 2);
  f = x - vec3(base);
}

// The texture coordinate of IJK point p (clamped to the volume): texel
// centres lie at (index + 0.5) / dimensions, so that the texture unit's
// trilinear interpolation there is the CPU's between voxel values.
vec3 filteredCoordinate(vec3 p) { return (clamp(p, vec3(0.0), vec3(dimensions - 1)) + 0.5) / dimensionsF; }

// The weights of the shader's own interpolation: float, or (FILTER_WEIGHT_STEPS,
// accuracy tests only) rounded to the fixed point of a texture unit's.
vec3 interpolationWeights(vec3 f)
{
#ifdef FILTER_WEIGHT_STEPS
  return round(f * FILTER_WEIGHT_STEPS) / FILTER_WEIGHT_STEPS;
#else
  return f;
#endif
}

// The CT at a cell's eight corners (named, not an array: arrays indexed at
// run time go to slow local memory on NVIDIA).
struct CellValues
{
  float v000;
  float v100;
  float v010;
  float v110;
  float v001;
  float v101;
  float v011;
  float v111;
};

CellValues cellValuesAt(ivec3 b)
{
  return CellValues(anatomyAt(b), anatomyAt(b + ivec3(1, 0, 0)), anatomyAt(b + ivec3(0, 1, 0)), anatomyAt(b + ivec3(1, 1, 0)),
    anatomyAt(b + ivec3(0, 0, 1)), anatomyAt(b + ivec3(1, 0, 1)), anatomyAt(b + ivec3(0, 1, 1)), anatomyAt(b + ivec3(1, 1, 1)));
}

#ifdef ANATOMY_FILTERED
// The texture unit's filtered R16 texel, value - anatomyMinimum over 65535:
// the CPU's trilinear value to within the unit's weight precision (see
// vtkVolumeCutOpenGLRayCaster::HardwareFiltering), one fetch instead of 8.
float intensity(vec3 p)
{
  return anatomyMinimum + 65535.0 * textureLod(anatomyTexture, filteredCoordinate(p), 0.0).r;
}
#else
float intensity(vec3 p)
{
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  f = interpolationWeights(f);
  CellValues c = cellValuesAt(b);
  float c00 = c.v000 + f.x * (c.v100 - c.v000);
  float c10 = c.v010 + f.x * (c.v110 - c.v010);
  float c01 = c.v001 + f.x * (c.v101 - c.v001);
  float c11 = c.v011 + f.x * (c.v111 - c.v011);
  float c0 = c00 + f.y * (c10 - c00);
  float c1 = c01 + f.y * (c11 - c01);
  return c0 + f.z * (c1 - c0);
}
#endif

vec4 styleColor(int label) { return texelFetch(styleTexture, ivec2(label, 0), 0); }
vec4 styleSurface(int label) { return texelFetch(styleTexture, ivec2(label, 1), 0); }
vec3 styleSurfaceColor(int label) { return texelFetch(styleTexture, ivec2(label, 2), 0).rgb; }

float cornerWeight(int corner, vec3 f)
{
  return ((corner & 1) != 0 ? f.x : 1.0 - f.x) * ((corner & 2) != 0 ? f.y : 1.0 - f.y) * ((corner & 4) != 0 ? f.z : 1.0 - f.z);
}

ivec3 cornerOffset(int corner) { return ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1); }

vec4 fractionsAt(vec3 p)
{
#ifdef FRACTIONS_FILTERED
  return textureLod(fractionTexture, filteredCoordinate(p), 0.0);
#else
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  f = interpolationWeights(f);
  vec4 value = vec4(0.0);
  for (int corner = 0; corner < 8; ++corner)
  {
    value += cornerWeight(corner, f) * texelFetch(fractionTexture, b + cornerOffset(corner), 0);
  }
  return value;
#endif
}

bool shownIsoSegment(int label)
{
  return label > 0 && label < styleCount && styleColor(label).a > 0.0 && styleSurface(label).y <= 0.5;
}

// The segment of greatest weight at p (vtkVolumeCutSampleClassifier::
// StrongestLabel). materialOnly: only the corners of shown iso-defined
// segments inside their surface count (MaterialOwner); otherwise every
// labelled corner, and unlabelled bright material competes (DominantLabel).
int strongestLabel(vec3 p, bool materialOnly, out float weight)
{
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  int labels[12];
  float weights[12];
  int count = 0;
  float unlabelledBright = 0.0;
  for (int corner = 0; corner < 8 && hasLabelMap != 0; ++corner)
  {
    int label = labelAt(b + cornerOffset(corner));
    float w = cornerWeight(corner, f);
    if (materialOnly)
    {
      if (!shownIsoSegment(label) || anatomyAt(b + cornerOffset(corner)) < styleSurface(label).x)
      {
        continue;
      }
    }
    else if (label == 0)
    {
      if (anyIso != 0 && anatomyAt(b + cornerOffset(corner)) >= minimumIso)
      {
        unlabelledBright += w;
      }
      continue;
    }
    int slot = 0;
    while (slot < count && labels[slot] != label)
    {
      ++slot;
    }
    if (slot == count)
    {
      labels[count] = label;
      weights[count] = 0.0;
      ++count;
    }
    weights[slot] += w;
  }
  if (fractionCount > 0)
  {
    vec4 fractions = fractionsAt(p);
    for (int i = 0; i < fractionCount; ++i)
    {
      int label = int(fractionLabels[i] + 0.5);
      if (materialOnly && !shownIsoSegment(label))
      {
        continue;
      }
      int slot = 0;
      while (slot < count && labels[slot] != label)
      {
        ++slot;
      }
      if (slot == count)
      {
        labels[count] = label;
        ++count;
      }
      weights[slot] = fractions[i];
    }
  }
  int best = 0;
  weight = 0.0;
  for (int slot = 0; slot < count; ++slot)
  {
    if (weights[slot] > weight || (weights[slot] == weight && weight > 0.0 && labels[slot] < best))
    {
      best = labels[slot];
      weight = weights[slot];
    }
  }
  if (!materialOnly && unlabelledBright > weight)
  {
    return 0;
  }
  return best;
}

int dominantLabel(vec3 p, out float weight) { return strongestLabel(p, false, weight); }

// The segment whose material lies under an iso-surface point (0 for none).
int materialOwner(vec3 p)
{
  float weight;
  return strongestLabel(p, true, weight);
}

float indicator(int label, vec3 p)
{
  for (int i = 0; i < fractionCount; ++i)
  {
    if (int(fractionLabels[i] + 0.5) == label)
    {
      return fractionsAt(p)[i];
    }
  }
  if (hasLabelMap == 0)
  {
    return 0.0;
  }
  ivec3 b;
  vec3 f;
  cellOf(p, b, f);
  float value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    if (labelAt(b + cornerOffset(corner)) == label)
    {
      value += cornerWeight(corner, f);
    }
  }
  return value;
}

int objectAt(vec3 p, out float value)
{
  value = intensity(p);
  if (hasLabels == 0)
  {
    vec4 s = styleSurface(1);
    return (styleColor(1).a > 0.0 && value >= s.x) ? 1 : 0;
  }
  float weight;
  int label = dominantLabel(p, weight);
  if (label == 0 || label >= styleCount || styleColor(label).a <= 0.0)
  {
    return 0;
  }
  vec4 s = styleSurface(label);
  bool inside = s.y > 0.5 ? weight >= 0.5 : value >= s.x;
  return inside ? label : 0;
}

Sample sampleAt(float t)
{
  Sample s;
  s.t = t;
  s.index = rayOrigin + t * rayDirection;
  s.object = 0;
  s.value = 0.0;
  s.cutsKnown = false;
  for (int n = 0; n < CUT_SLOTS; ++n)
  {
    s.distance[n] = 1.0;
  }
  return s;
}

void evaluateObject(inout Sample s) { s.object = objectAt(s.index, s.value); }

vec3 worldPoint(vec3 index) { return (ijkToWorld * vec4(index, 1.0)).xyz; }
