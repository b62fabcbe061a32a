// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkHapticPointShell
 * @brief   Points on a tool's surface, where contact with the anatomy is felt.
 *
 * The Voxmap-PointShell idea as seed 003 uses it (82 points around a burr):
 * the tool is sampled by points spread over its surface, each tested for
 * contact every haptic tick. Directions come from a spiral on the unit
 * sphere (Saff and Kuijlaars) that spreads any number of points evenly and
 * passes through both poles, so that a tool pressed along its axis touches
 * first with a shell point exactly at its tip. On a spherical burr the
 * points are the directions times the radius; on any other tool (cylinder
 * burr, disk saw, blade, mesh) each direction is followed from the tool's
 * origin to its surface (bisection on the tool's signed distance), which
 * needs the tool to be star-shaped about its origin, as burrs and saws are.
 *
 * Points are in the tool's frame (mm). Built on the main thread; read by the
 * haptic thread, never changed while a loop runs.
 *
 * @sa vtkHapticForceModel
 */

#ifndef vtkHapticPointShell_h
#define vtkHapticPointShell_h

#include "vtkObject.h"
#include "vtkVolumeCuttingHapticsExport.h" // For export macro

#include <vector> // For the points

class vtkVolumeCutTool;

class VTK_VOLUMECUTTINGHAPTICS_EXPORT vtkHapticPointShell : public vtkObject
{
public:
  static vtkHapticPointShell* New();
  vtkTypeMacro(vtkHapticPointShell, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get the number of points the next Build places (6 to 4096). Default is 82.
   */
  vtkSetClampMacro(NumberOfPointsToBuild, int, 6, 4096);
  vtkGetMacro(NumberOfPointsToBuild, int);
  ///@}

  /// Points on a sphere of this radius (mm) about the origin. False (and an error) for a radius that is not positive.
  bool BuildSphere(double radius);

  /**
   * Points on the surface of a tool. False (and an error), leaving the shell
   * as it was, for an invalid tool or one whose origin is not inside it.
   */
  bool BuildTool(vtkVolumeCutTool* tool);

  /// Number of points built (0 before a Build).
  int GetNumberOfPoints() const { return static_cast<int>(this->Points.size() / 3); }

  /// Point n (mm, tool frame).
  void GetPoint(int n, double point[3]) const;

#ifndef __VTK_WRAP__
  /// All points, x y z each (for the haptic thread).
  const double* GetPointData() const { return this->Points.data(); }
#endif

  /// The largest distance (mm) between a point and its nearest neighbour: how finely contact is sampled.
  double GetLargestSpacing() const;

protected:
  vtkHapticPointShell() = default;
  ~vtkHapticPointShell() override = default;

  int NumberOfPointsToBuild = 82;
  std::vector<double> Points;

private:
  vtkHapticPointShell(const vtkHapticPointShell&) = delete;
  void operator=(const vtkHapticPointShell&) = delete;
};

#endif
