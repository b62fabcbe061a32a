// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Composite mode: the transfer functions composited front to back, each
// step cut into pieces at the cut fields' borders and the removed pieces
// left out exactly; the first piece after a cut border is shaded with the
// cut's normal (vtkVolumeCutCompositor.h). Replaces the skeleton's
// VolumeCut::Composite::Dec tag.

uniform sampler2D transferTexture;  // composite mode: (rgb, opacity per unit distance)
uniform float unitDistance;
uniform vec2 tableRange;
uniform int tableSize;

vec4 lookUp(float value)
{
  float span = tableRange.y - tableRange.x;
  float x = span > 0.0 ? (value - tableRange.x) / span * float(tableSize - 1) : 0.0;
  x = clamp(x, 0.0, float(tableSize - 1));
  int i = min(int(x), tableSize - 2);
  float f = x - float(i);
  return mix(texelFetch(transferTexture, ivec2(i, 0), 0), texelFetch(transferTexture, ivec2(i + 1, 0), 0), f);
}

// Composite the step from a to b; lastCutBorder is the cut whose border the
// next piece starts at (-1 for none). True when the pixel is opaque.
bool compositeStep(inout Sample a, inout Sample b, inout int lastCutBorder)
{
  bool done = false;
  evaluateCuts(a);
  evaluateCuts(b);
  float borderT[CUT_SLOTS + 1];
  int borderCut[CUT_SLOTS + 1];
  int count = 0;
  for (int n = 0; n < NUMBER_OF_CUTS; ++n)
  {
    if ((a.distance[n] < 0.0) != (b.distance[n] < 0.0))
    {
      borderT[count] = bisectCut(n, a, b);
      borderCut[count] = n;
      ++count;
    }
  }
  sortBorders(borderT, borderCut, count);
  float startT = a.t;
  for (int piece = 0; piece <= count && !done; ++piece)
  {
    float endT = piece < count ? borderT[piece] : b.t;
    if (endT > startT)
    {
      Sample mid = sampleAt(0.5 * (startT + endT));
      evaluateObject(mid);
      evaluateCuts(mid);
      if (!removed(mid))
      {
        vec4 tf = lookUp(mid.value);
        if (tf.a > 0.0)
        {
          float alpha = 1.0 - pow(1.0 - min(tf.a, 0.9999), (endT - startT) / unitDistance);
          vec3 normal;
          if (lastCutBorder >= 0)
          {
            normal = cutNormal(lastCutBorder, worldPoint(mid.index));
          }
          else
          {
            vec3 gradient;
            for (int axis = 0; axis < 3; ++axis)
            {
              vec3 plus = mid.index;
              vec3 minus = mid.index;
              plus[axis] += gradientStep;
              minus[axis] -= gradientStep;
              gradient[axis] = intensity(minus) - intensity(plus);
            }
            // Where the CT is uniform there is no gradient: the piece is lit by
            // the ambient term alone, as on the CPU (normalize() of a zero
            // vector is NaN, which the driver may turn into full white).
            vec3 worldGradient = normalMatrix * gradient;
            float gradientLength = length(worldGradient);
            normal = gradientLength > 0.0 ? worldGradient / gradientLength : vec3(0.0);
          }
          record(startT, shade(tf.rgb, normal, viewVector), alpha, 0.02);
          done = accumulated.a >= 0.995;
        }
        lastCutBorder = -1;
      }
    }
    if (piece < count)
    {
      lastCutBorder = borderCut[piece];
    }
    startT = endT;
  }
  return done;
}
