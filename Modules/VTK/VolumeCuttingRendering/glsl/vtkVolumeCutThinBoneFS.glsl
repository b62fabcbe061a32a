// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Thin-bone shading (Morris et al.): bone thinner than thinBoneThickness
// along the inward normal turns red and translucent
// (vtkVolumeCutThinBoneShader.h). Replaces the skeleton's VolumeCut::ThinBone::Dec tag.

uniform int thinBone;
uniform float thinBoneThickness;

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
    Sample s = sampleAt(0.0);
    s.index = index + travelled * inwardIndex;
    if (any(lessThan(s.index, vec3(0.0))) || any(greaterThan(s.index, vec3(dimensions - 1))))
    {
      return thinBoneThickness;
    }
    evaluateObject(s);
    if (!visible(s))
    {
      return travelled;
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
