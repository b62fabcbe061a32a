// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Step 4 of adaptive sampling, shading: the normal of the field whose border
// starts the first visible piece, a headlight's Phong lighting, thin bone,
// and front-to-back compositing into the pixel (vtkVolumeCutSurfaceShader.h,
// vtkVolumeCutRayResult.h). Replaces the skeleton's VolumeCut::Shading::Dec tag.

uniform float gradientStep;
uniform float ambientK;
uniform float diffuseK;
uniform float specularK;
uniform float specularPower;

// The object field's gradient by 3D Sobel differences gradientStep voxels
// apart: no contour rings where partial volume ramps a surface
// (vtkVolumeCutSurfaceShader::SobelGradient says why).
vec3 objectNormal(int object, vec3 p)
{
  vec3 gradient = vec3(0.0);
  bool shape = hasLabels != 0 && styleSurface(object).y > 0.5;
  for (int k = -1; k <= 1; ++k)
  {
    for (int j = -1; j <= 1; ++j)
    {
      for (int i = -1; i <= 1; ++i)
      {
        if (i == 0 && j == 0 && k == 0)
        {
          continue;
        }
        vec3 o = vec3(float(i), float(j), float(k));
        vec3 q = p + gradientStep * o;
        float value = shape ? indicator(object, q) : intensity(q);
        // Weight 2 where the point lies on the axis's line across, 1 off it.
        vec3 w = vec3(i == 0 ? 2.0 : 1.0, j == 0 ? 2.0 : 1.0, k == 0 ? 2.0 : 1.0);
        gradient += value * o * vec3(w.y * w.z, w.x * w.z, w.x * w.y);
      }
    }
  }
  return normalize(-(normalMatrix * gradient));
}

vec3 cutNormal(int n, vec3 world)
{
  float h = cutStepOf(n);
  vec3 normal;
  for (int axis = 0; axis < 3; ++axis)
  {
    vec3 plus = world;
    vec3 minus = world;
    plus[axis] += h;
    minus[axis] -= h;
    normal[axis] = cutDistance(n, minus) - cutDistance(n, plus);
  }
  return normalize(normal);
}

vec3 shade(vec3 color, vec3 normal, vec3 view)
{
  float cosine = abs(dot(normal, view));
  float specular = specularK * pow(cosine, specularPower);
  return min(vec3(1.0), color * (ambientK + diffuseK * cosine) + vec3(specular));
}

void record(float t, vec3 rgb, float alpha, float minimumAlpha)
{
  float remaining = 1.0 - accumulated.a;
  accumulated.rgb += remaining * alpha * rgb;
  accumulated.a += remaining * alpha;
  if (firstHit && alpha >= minimumAlpha)
  {
    firstHit = false;
    vec4 clip = worldToNDC * vec4(originWorld + t * directionWorld, 1.0);
    hitDepth = clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0);
  }
}

bool enter(Sample piece, float t, int source)
{
  vec3 index = rayOrigin + t * rayDirection;
  vec3 normal;
  int owner = piece.object;
  if (source == SOURCE_OBJECT)
  {
    normal = objectNormal(piece.object, index);
    // Coloured as the material under it, not as the voxels it crosses.
    if (hasLabels != 0 && styleSurface(piece.object).y <= 0.5)
    {
      int material = materialOwner(index);
      owner = material > 0 ? material : owner;
    }
  }
  else if (source >= SOURCE_CUT)
  {
    normal = cutNormal(source - SOURCE_CUT, worldPoint(index));
  }
  else
  {
    normal = entryNormal;
  }
  // Occlusion and thin bone keep the outward estimate (vtkVolumeCutSurfaceShader::Enter says why).
  vec3 outward = normal;
  if (dot(normal, viewVector) < 0.0)
  {
    normal = -normal;
  }
  vec4 style = styleColor(owner);
  vec3 rgb = shade(source == SOURCE_OBJECT ? styleSurfaceColor(owner) : style.rgb, normal, viewVector);
  float alpha = style.a;
  if (ambientOcclusion != 0)
  {
    rgb *= 1.0 - 0.9 * occlusion(index, outward);
    rgb *= cavityShade(index, viewVector);
  }
  // Not on the scan's end faces or clip planes (vtkVolumeCutSurfaceShader::Enter says why).
  if (thinBone != 0 && (source == SOURCE_OBJECT || source >= SOURCE_CUT))
  {
    applyThinBone(piece.object, index, outward, rgb, alpha);
  }
  record(t, rgb, alpha, 0.0);
  ++layers;
  return accumulated.a >= 0.995 || layers >= 8;
}
