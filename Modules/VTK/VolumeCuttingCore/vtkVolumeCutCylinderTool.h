// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutCylinderTool
 * @brief   Cylinder along the local z axis, centred on the origin.
 *
 * A cylindrical (fissure) burr, or with a short length a disk saw.
 */

#ifndef vtkVolumeCutCylinderTool_h
#define vtkVolumeCutCylinderTool_h

#include "vtkVolumeCutTool.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutCylinderTool : public vtkVolumeCutTool
{
public:
  static vtkVolumeCutCylinderTool* New();
  vtkTypeMacro(vtkVolumeCutCylinderTool, vtkVolumeCutTool);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the radius and the length (mm, along z). Defaults are 1 and 4.
   */
  vtkSetMacro(Radius, double);
  vtkGetMacro(Radius, double);
  vtkSetMacro(Length, double);
  vtkGetMacro(Length, double);
  ///@}

  double EvaluateDistance(const double local[3]) override;
  VTK_WRAPEXCLUDE void EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances) override;
  double GetBoundingRadius() override;
  void GetLocalHalfExtents(double halfExtents[3]) override;
  bool IsValid() override;
  bool IsLeftBehind(const double center[3], double radius, const double motion[3]) override;
  VTK_WRAPEXCLUDE bool EvaluateTranslatedDistances(
    const double motion[3], double step, const float* x, const float* y, const float* z, int count, float* distances) override;
  VTK_WRAPEXCLUDE bool BoundTranslatedDistances(const double motion[3], double step, const double origin[3], const double stride[3],
    const double edges[2][3], int count, double* bounds) override;

protected:
  vtkVolumeCutCylinderTool() = default;
  ~vtkVolumeCutCylinderTool() override = default;

  double Radius = 1.0;
  double Length = 4.0;

private:
  vtkVolumeCutCylinderTool(const vtkVolumeCutCylinderTool&) = delete;
  void operator=(const vtkVolumeCutCylinderTool&) = delete;
};

#endif
