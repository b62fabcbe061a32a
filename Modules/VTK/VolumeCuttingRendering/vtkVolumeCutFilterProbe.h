// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutFilterProbe
 * @brief   How finely a context's texture unit interpolates 16-bit texels (vtkVolumeCutOpenGLRayCaster's FilterWeightError).
 *
 * Texture units weight texels with fixed-point fractions, commonly of 8
 * bits; where they do, the CT filtered by the unit moves an iso-surface by
 * more than the CPU/GPU tolerance, so the caster filters in the shader
 * instead. The probe draws a row of GL_LINEAR samples of a 2-texel R16
 * texture (0 and 65535) at points off any grid of 2^-n steps into a float
 * target and compares them with the exact lerp. It is measured once a
 * context: a driver that cannot filter R16 is not probed again every frame.
 */
#ifndef vtkVolumeCutFilterProbe_h
#define vtkVolumeCutFilterProbe_h

class vtkOpenGLRenderWindow;

class vtkVolumeCutFilterProbe
{
public:
  vtkVolumeCutFilterProbe() = default;
  vtkVolumeCutFilterProbe(const vtkVolumeCutFilterProbe&) = delete;
  void operator=(const vtkVolumeCutFilterProbe&) = delete;

  /// Measure the error in window's context (current) unless measured since the last Forget().
  void MeasureOnce(vtkOpenGLRenderWindow* window);

  /// Whether the error was measured in this context.
  bool GetMeasured() const { return this->Measured; }

  /**
   * The largest difference, over 1021 points, between GL_LINEAR between
   * two R16 texels 0 and 65535 and the exact lerp, a fraction of their
   * difference (2^-9 for weights rounded to 8 bits, about 1e-7 for float
   * weights); -1 before it was measured, or where the driver cannot filter
   * R16 or draw into a float target.
   */
  double GetFilterWeightError() const { return this->FilterWeightError; }

  /// The context is gone: the next context is measured again.
  void Forget();

  /// One measurement in window's context (current), as GetFilterWeightError() describes it.
  static double Measure(vtkOpenGLRenderWindow* window);

private:
  double FilterWeightError = -1.0;
  bool Measured = false;
};

#endif
