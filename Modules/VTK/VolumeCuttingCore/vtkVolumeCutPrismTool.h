// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutPrismTool
 * @brief   A planar polygon extruded along the local z axis: sawing.
 *
 * Sawing (Wang and Kaufman, Volume Sculpting): the user draws a 2D region on
 * the view, which is extruded along the viewing direction to a chosen depth.
 * The polygon lies in the local xy plane (mm, any simple polygon, convex or
 * not); the prism spans z from 0 to Depth. Place it with a pose whose z axis
 * is the sawing direction.
 */

#ifndef vtkVolumeCutPrismTool_h
#define vtkVolumeCutPrismTool_h

#include "vtkVolumeCutTool.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <vector> // For the polygon

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutPrismTool : public vtkVolumeCutTool
{
public:
  static vtkVolumeCutPrismTool* New();
  vtkTypeMacro(vtkVolumeCutPrismTool, vtkVolumeCutTool);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The polygon's vertices in the local xy plane (mm), in order, not repeated.
   */
  void RemoveAllVertices();
  void AddVertex(double x, double y);
  int GetNumberOfVertices() const { return static_cast<int>(this->Vertices.size() / 2); }
  ///@}

  ///@{
  /**
   * Set/get the extrusion depth (mm) along local +z. Default is 5.
   */
  vtkSetMacro(Depth, double);
  vtkGetMacro(Depth, double);
  ///@}

  double EvaluateDistance(const double local[3]) override;
  double GetBoundingRadius() override;
  bool IsValid() override;

protected:
  vtkVolumeCutPrismTool() = default;
  ~vtkVolumeCutPrismTool() override = default;

  std::vector<double> Vertices;
  double Depth = 5.0;

private:
  vtkVolumeCutPrismTool(const vtkVolumeCutPrismTool&) = delete;
  void operator=(const vtkVolumeCutPrismTool&) = delete;
};

#endif
