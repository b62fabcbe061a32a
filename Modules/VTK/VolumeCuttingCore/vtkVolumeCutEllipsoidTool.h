// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutEllipsoidTool
 * @brief   Ellipsoid centred on the local origin, semi-axes along the local axes.
 *
 * An ellipsoidal (acorn or barrel) burr. The distance is the classic
 * first-order approximation k0 (k0 - 1) / k1 (k0 = |p / r|, k1 = |p / r^2|):
 * its zero level is the exact ellipsoid and it is exact to first order near
 * the surface, where the cut field stores it.
 */

#ifndef vtkVolumeCutEllipsoidTool_h
#define vtkVolumeCutEllipsoidTool_h

#include "vtkVolumeCutTool.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutEllipsoidTool : public vtkVolumeCutTool
{
public:
  static vtkVolumeCutEllipsoidTool* New();
  vtkTypeMacro(vtkVolumeCutEllipsoidTool, vtkVolumeCutTool);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the semi-axes (mm) along local x, y, z. Default 1.5, 1.5, 2.5.
   */
  vtkSetVector3Macro(Radii, double);
  vtkGetVector3Macro(Radii, double);
  ///@}

  double EvaluateDistance(const double local[3]) override;
  VTK_WRAPEXCLUDE void EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances) override;
  double GetBoundingRadius() override;
  bool IsValid() override;

protected:
  vtkVolumeCutEllipsoidTool() = default;
  ~vtkVolumeCutEllipsoidTool() override = default;

  double Radii[3] = { 1.5, 1.5, 2.5 };

private:
  vtkVolumeCutEllipsoidTool(const vtkVolumeCutEllipsoidTool&) = delete;
  void operator=(const vtkVolumeCutEllipsoidTool&) = delete;
};

#endif
