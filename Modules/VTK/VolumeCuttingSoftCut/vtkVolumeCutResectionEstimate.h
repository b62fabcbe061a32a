// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutResectionEstimate
 * @brief   The resected tissue of a SoftCut plan as a mesh, with its measurements.
 *
 * Section 3.6 of Blache et al.: the surgeon measures the resection and
 * prints it as a guide for harvesting a flap. The resected tissue at a depth
 * of cut (vtkVolumeCutResectionPlanner::BuildResectedTissueFunction: between
 * the skin and the depth, inside the wall, short of bone) is contoured with
 * flying edges at sub-voxel resolution and smoothed with a windowed-sinc
 * filter, which moves points without shrinking the volume as Laplacian
 * smoothing would. Measurements are taken on the smoothed mesh: the enclosed
 * volume and area by the divergence theorem, and the extents in a local
 * frame: origin at the volume's centroid, thickness along the outline's
 * average normal, length and width along the principal axes of the mesh seen
 * along that normal. The mesh is closed and its normals point outwards,
 * ready for an STL file (3D printing).
 *
 * @sa vtkVolumeCutResectionPlanner
 */

#ifndef vtkVolumeCutResectionEstimate_h
#define vtkVolumeCutResectionEstimate_h

#include "vtkObject.h"
#include "vtkSmartPointer.h"                // For the planner and the mesh
#include "vtkVolumeCuttingSoftCutExport.h" // For export macro

#include <string> // For the error message

class vtkPolyData;
class vtkVolumeCutResectionPlanner;

class VTK_VOLUMECUTTINGSOFTCUT_EXPORT vtkVolumeCutResectionEstimate : public vtkObject
{
public:
  static vtkVolumeCutResectionEstimate* New();
  vtkTypeMacro(vtkVolumeCutResectionEstimate, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /** Set/get the planner whose plan is measured. Default is none. */
  void SetPlanner(vtkVolumeCutResectionPlanner* planner);
  vtkVolumeCutResectionPlanner* GetPlanner() const;
  ///@}

  ///@{
  /** Set/get the depth of cut (mm). Default is 5. */
  vtkSetMacro(Depth, double);
  vtkGetMacro(Depth, double);
  ///@}

  ///@{
  /**
   * Set/get how many samples per voxel (1 or 2, along each axis) the
   * contoured function has. Default is 2.
   */
  vtkSetClampMacro(Subdivision, int, 1, 2);
  vtkGetMacro(Subdivision, int);
  ///@}

  ///@{
  /**
   * Set/get the iterations of windowed-sinc smoothing (0: none) and its pass
   * band (0..2; lower smooths more). Defaults are 20 and 0.1.
   */
  vtkSetClampMacro(SmoothingIterations, int, 0, 1000);
  vtkGetMacro(SmoothingIterations, int);
  vtkSetClampMacro(PassBand, double, 0.001, 2.0);
  vtkGetMacro(PassBand, double);
  ///@}

  /**
   * Contour, smooth and measure. Returns false with a message (the
   * planner's) without a plan or for a bad depth; the last results stay.
   */
  bool Update();

  /// What went wrong in the last Update that returned false.
  const char* GetErrorMessage() const { return this->ErrorMessage.c_str(); }

  /// The smoothed mesh (RAS, mm; closed triangles, outward normals).
  vtkPolyData* GetSurface() const;

  ///@{
  /**
   * Measurements of the smoothed mesh: volume (mm^3) and area (mm^2); the
   * volume of the contour before smoothing, for comparison.
   */
  vtkGetMacro(Volume, double);
  vtkGetMacro(SurfaceArea, double);
  vtkGetMacro(ContourVolume, double);
  ///@}

  ///@{
  /**
   * The local frame (RAS): origin at the centroid of the volume; axes 0 and
   * 1 (length and width) the principal directions of the mesh across the
   * average normal, axis 2 (thickness) the outline's average outward normal;
   * and the extents (mm) of the mesh along them.
   */
  vtkGetVector3Macro(FrameOrigin, double);
  void GetFrameAxis(int axis, double direction[3]) const;
  vtkGetVector3Macro(Extents, double);
  ///@}

protected:
  vtkVolumeCutResectionEstimate();
  ~vtkVolumeCutResectionEstimate() override;

  vtkSmartPointer<vtkVolumeCutResectionPlanner> Planner;
  vtkSmartPointer<vtkPolyData> Surface;
  double Depth = 5.0;
  int Subdivision = 2;
  int SmoothingIterations = 20;
  double PassBand = 0.1;
  double Volume = 0.0;
  double SurfaceArea = 0.0;
  double ContourVolume = 0.0;
  double FrameOrigin[3] = { 0.0, 0.0, 0.0 };
  double FrameAxes[3][3] = { { 1.0, 0.0, 0.0 }, { 0.0, 1.0, 0.0 }, { 0.0, 0.0, 1.0 } };
  double Extents[3] = { 0.0, 0.0, 0.0 };
  std::string ErrorMessage;

private:
  vtkVolumeCutResectionEstimate(const vtkVolumeCutResectionEstimate&) = delete;
  void operator=(const vtkVolumeCutResectionEstimate&) = delete;
};

#endif
