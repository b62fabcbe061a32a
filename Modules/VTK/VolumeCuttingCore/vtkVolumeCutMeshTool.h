// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutMeshTool
 * @brief   Any closed triangle surface as a tool, in its own frame.
 *
 * A custom burr or implant-shaped cutter from a surface model. The surface
 * must be closed and manifold (no boundary or non-manifold edges): otherwise
 * inside and outside are undefined and IsValid refuses it.
 */

#ifndef vtkVolumeCutMeshTool_h
#define vtkVolumeCutMeshTool_h

#include "vtkNew.h" // For the distance function
#include "vtkVolumeCutTool.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

class vtkImplicitPolyDataDistance;
class vtkPolyData;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutMeshTool : public vtkVolumeCutTool
{
public:
  static vtkVolumeCutMeshTool* New();
  vtkTypeMacro(vtkVolumeCutMeshTool, vtkVolumeCutTool);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Set the tool's surface (copied), in the tool's frame (mm).
  void SetSurface(vtkPolyData* surface);

  double EvaluateDistance(const double local[3]) override;
  double GetBoundingRadius() override;
  bool IsValid() override;

protected:
  vtkVolumeCutMeshTool();
  ~vtkVolumeCutMeshTool() override;

  vtkNew<vtkImplicitPolyDataDistance> Distance;
  double BoundingRadius = 0.0;
  bool Closed = false;
  vtkIdType NumberOfTriangles = 0;

private:
  vtkVolumeCutMeshTool(const vtkVolumeCutMeshTool&) = delete;
  void operator=(const vtkVolumeCutMeshTool&) = delete;
};

#endif
