// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped): 4x4
// row-major matrices applied to points and vectors, as the ray stages of
// vtkVolumeCutRayCaster use them (no vtkMatrix4x4 in the per-sample code).
#ifndef vtkVolumeCutRayMath_h
#define vtkVolumeCutRayMath_h

namespace vtkVolumeCutRayMath
{
inline void Multiply4(const double m[16], const double in[4], double out[4])
{
  for (int row = 0; row < 4; ++row)
  {
    out[row] = m[4 * row] * in[0] + m[4 * row + 1] * in[1] + m[4 * row + 2] * in[2] + m[4 * row + 3] * in[3];
  }
}

inline void TransformPoint(const double m[16], const double in[3], double out[3])
{
  const double h[4] = { in[0], in[1], in[2], 1.0 };
  double r[4];
  Multiply4(m, h, r);
  out[0] = r[0];
  out[1] = r[1];
  out[2] = r[2];
}

inline void TransformVector(const double m[16], const double in[3], double out[3])
{
  for (int row = 0; row < 3; ++row)
  {
    out[row] = m[4 * row] * in[0] + m[4 * row + 1] * in[1] + m[4 * row + 2] * in[2];
  }
}
}

#endif
