// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutBoxTool
 * @brief   Box centred on the local origin, edges along the local axes.
 *
 * With one thin side, a blade (scalpel or osteotome); sweeping it cuts a slot.
 */

#ifndef vtkVolumeCutBoxTool_h
#define vtkVolumeCutBoxTool_h

#include "vtkVolumeCutTool.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutBoxTool : public vtkVolumeCutTool
{
public:
  static vtkVolumeCutBoxTool* New();
  vtkTypeMacro(vtkVolumeCutBoxTool, vtkVolumeCutTool);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the full edge lengths (mm) along local x, y, z. Default 10, 0.5, 5.
   */
  vtkSetVector3Macro(Size, double);
  vtkGetVector3Macro(Size, double);
  ///@}

  double EvaluateDistance(const double local[3]) override;
  VTK_WRAPEXCLUDE void EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances) override;
  double GetBoundingRadius() override;
  void GetLocalHalfExtents(double halfExtents[3]) override;
  bool IsValid() override;
  bool IsLeftBehind(const double center[3], double radius, const double motion[3]) override;

protected:
  vtkVolumeCutBoxTool() = default;
  ~vtkVolumeCutBoxTool() override = default;

  double Size[3] = { 10.0, 0.5, 5.0 };

private:
  vtkVolumeCutBoxTool(const vtkVolumeCutBoxTool&) = delete;
  void operator=(const vtkVolumeCutBoxTool&) = delete;
};

#endif
