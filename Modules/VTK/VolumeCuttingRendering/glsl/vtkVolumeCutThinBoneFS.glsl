// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Thin-bone shading (Morris et al.): bone thinner than thinBoneThickness
// along the inward normal turns red and translucent
// (vtkVolumeCutThinBoneShader.h, which says why the last step is halved and
// why a sliver without material is crossed).
// Replaces the skeleton's VolumeCut::ThinBone::Dec tag.

uniform int thinBone;
uniform float thinBoneThickness;

bool visibleAt(vec3 index)
{
  Sample s = sampleAt(0.0);
  s.index = index;
  evaluateObject(s);
  return visible(s);
}

bool insideVolume(vec3 p)
{
  return !(any(lessThan(p, vec3(0.0))) || any(greaterThan(p, vec3(dimensions - 1))));
}

// Whether material is visible again within six steps (a voxel and a half)
// beyond a sample without it, and how far along: the sliver between two
// shown segments' smoothed labels and the notch under a slice drawn larger
// than the next are part of the wall
// (vtkVolumeCutThinBoneShader::GapBridgeSteps says why).
bool materialAgainWithin(vec3 index, vec3 inwardIndex, float stepLength, inout float travelled)
{
  for (int ahead = 1; ahead <= 6; ++ahead)
  {
    vec3 p = index + (travelled + float(ahead) * stepLength) * inwardIndex;
    if (!insideVolume(p))
    {
      return false;
    }
    if (visibleAt(p))
    {
      travelled += float(ahead) * stepLength;
      return true;
    }
  }
  return false;
}

// Where the material ends between two distances (mm) along the inward
// direction: in it at inside, out at outside.
float thinBoneCrossing(vec3 index, vec3 inwardIndex, float inside, float outside)
{
  for (int halving = 0; halving < 6; ++halving)
  {
    float middle = 0.5 * (inside + outside);
    if (visibleAt(index + middle * inwardIndex))
    {
      inside = middle;
    }
    else
    {
      outside = middle;
    }
  }
  return 0.5 * (inside + outside);
}

float measureThickness(int object, vec3 index, vec3 normalWorld)
{
  vec3 inwardIndex = mat3(worldToIJK) * (-normalWorld);
  float voxelsPerMillimetre = length(inwardIndex);
  if (voxelsPerMillimetre <= 0.0)
  {
    return thinBoneThickness;
  }
  float stepLength = 0.25 / voxelsPerMillimetre;
  for (float travelled = stepLength; travelled < thinBoneThickness; travelled += stepLength)
  {
    vec3 p = index + travelled * inwardIndex;
    if (!insideVolume(p))
    {
      return thinBoneThickness;
    }
    if (!visibleAt(p))
    {
      float beyond = travelled;
      if (!materialAgainWithin(index, inwardIndex, stepLength, beyond))
      {
        return thinBoneCrossing(index, inwardIndex, travelled - stepLength, travelled);
      }
      travelled = beyond;
    }
  }
  return thinBoneThickness;
}

void applyThinBone(int object, vec3 index, vec3 normal, inout vec3 rgb, inout float alpha)
{
  float thickness = measureThickness(object, index, normal);
  if (thickness < thinBoneThickness)
  {
    float f = thickness / thinBoneThickness;
    rgb = mix(vec3(1.0, 0.12, 0.08), rgb, f);
    alpha *= 0.3 + 0.7 * f;
  }
}
