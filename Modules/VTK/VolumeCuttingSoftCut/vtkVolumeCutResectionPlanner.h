// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutResectionPlanner
 * @brief   SoftCut: a soft-tissue resection from an outline drawn on the skin.
 *
 * Blache et al., SoftCut (seed 002, section 3): the surgeon draws the outline
 * of a resection on the skin of the patient's CT, and the planner propagates
 * it into the volume and measures the depth of every voxel under it, so that
 * the depth of cut can be changed and previewed at once, then carved.
 *
 * 1. Outline: a closed polyline (RAS) near the skin, the CT's iso-surface at
 *    SkinIsoValue. Every point is moved along the image gradient onto the
 *    skin; a point farther than SkinTolerance is refused.
 * 2. Strips (section 3.2): each outline point offset by StripOffset in the
 *    skin's tangent plane to either side, perpendicular to the outline and
 *    to the normal: the local normal (the inverse image gradient, smoothed
 *    along the outline) or the outline's average normal (NormalMode). The
 *    inner strip is the offset towards the inside of the outline as seen
 *    along the average normal (the paper takes the shorter strip, which is
 *    the same for the outlines it assumes, but not for caps larger than a
 *    hemisphere).
 * 3. Shape (section 3.3): inside a bounding box, one exact Euclidean distance
 *    transform towards each strip (vtkVolumeCutDistanceTransform); the shape
 *    is where the inner strip is nearer. Its wall is located to a fraction of
 *    a voxel from the exact distances to the strips' segments (the
 *    transforms say which segment is near) and their gradients. A flood fill
 *    from the skin inside the outline takes the voxels of the shape whose
 *    value lies in SoftTissueRange: bone and air stop it, so tissue behind
 *    bone or across an air cavity is never part of the resection.
 * 4. Mask (section 3.4): a third transform from the skin inside the outline
 *    gives every voxel its depth under the skin, measured to the skin's
 *    sub-voxel surface (the tangent plane at the nearest skin voxel).
 * 5. The region for a depth of cut (section 3.5): where the shape, the depth
 *    and the filled tissue agree, as signed distances for
 *    vtkVolumeCutField::CutSampledRegion, with the voxels that must stay (bone
 *    and the tissue the fill did not reach) as voxel cubes. Changing the depth
 *    reuses the mask: nothing is recomputed but the region's few images.
 *
 * The bounding box holds the strips, the outline moved MaximumDepth along
 * its normals and a margin; where the skin inside the outline or the tissue
 * within MaximumDepth reaches the box, the box grows and the planning is
 * repeated (Plan). Grids may be anisotropic and flipped, but their axes must
 * be orthogonal.
 *
 * Errors (an outline that is not closed or has fewer than three points, that
 * crosses itself, that leaves the skin; a depth that is not positive or beyond
 * MaximumDepth; an outline enclosing no soft tissue) make the methods return
 * false with a message (GetErrorMessage, also logged) and change nothing
 * already planned or carved.
 *
 * @sa vtkVolumeCutResectionEstimate vtkVolumeCutField::CutSampledRegion
 */

#ifndef vtkVolumeCutResectionPlanner_h
#define vtkVolumeCutResectionPlanner_h

#include "vtkObject.h"
#include "vtkSmartPointer.h"                // For the inputs
#include "vtkVolumeCuttingSoftCutExport.h" // For export macro

#include <memory> // For std::unique_ptr
#include <string> // For the error message

class vtkImageData;
class vtkMatrix4x4;
class vtkPoints;
class vtkPolyData;
class vtkVolumeCutField;

class VTK_VOLUMECUTTINGSOFTCUT_EXPORT vtkVolumeCutResectionPlanner : public vtkObject
{
public:
  static vtkVolumeCutResectionPlanner* New();
  vtkTypeMacro(vtkVolumeCutResectionPlanner, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// How the strips are offset from the outline (section 3.2 of the paper).
  enum NormalModes
  {
    /// Perpendicular to each point's own normal: the resection follows the
    /// skin's normals inwards (curved regions: nose, chin).
    LocalNormal = 0,
    /// Perpendicular to the outline's average normal: the resection goes in
    /// along one direction (flatter regions: cheek, forehead).
    AverageNormal = 1
  };

  /**
   * The CT (first scalar component, Hounsfield units) and where its voxels
   * are: IJK to RAS (nullptr: the image's own origin, spacing and direction).
   * The image's extent must start at 0.
   */
  void SetAnatomy(vtkImageData* image, vtkMatrix4x4* ijkToRAS);

  /**
   * The outline: points (RAS, mm) along a closed curve on the skin, in order;
   * the last connects to the first (a repeated first point at the end is
   * dropped). Densely sampled curves (a markups curve's curve points) are
   * what the planner expects; it resamples them itself.
   */
  void SetOutline(vtkPoints* points);

  ///@{
  /**
   * Set/get the normal the strips are built with (LocalNormal or
   * AverageNormal). Default is LocalNormal.
   */
  vtkSetClampMacro(NormalMode, int, LocalNormal, AverageNormal);
  vtkGetMacro(NormalMode, int);
  ///@}

  ///@{
  /**
   * Set/get the CT value (HU) of the skin's iso-surface: air below, tissue
   * above. Default is -500.
   */
  vtkSetMacro(SkinIsoValue, double);
  vtkGetMacro(SkinIsoValue, double);
  ///@}

  ///@{
  /**
   * Set/get the CT values (HU) of the soft tissue the resection may take:
   * the flood fill stops at voxels outside this range (bone above, air
   * below), and no voxel above it is ever removed. Default is -500 to 250.
   */
  vtkSetVector2Macro(SoftTissueRange, double);
  vtkGetVector2Macro(SoftTissueRange, double);
  ///@}

  ///@{
  /**
   * Set/get the distance (mm) between the outline and each strip; 0 takes
   * twice the largest voxel spacing. Default is 0.
   */
  vtkSetClampMacro(StripOffset, double, 0.0, 100.0);
  vtkGetMacro(StripOffset, double);
  ///@}

  ///@{
  /**
   * Set/get the deepest depth of cut (mm) the plan prepares: the mask is
   * built to this depth under the skin, and a deeper cut needs a new plan.
   * Default is 30.
   */
  vtkSetClampMacro(MaximumDepth, double, 0.0, 1.0e4);
  vtkGetMacro(MaximumDepth, double);
  ///@}

  ///@{
  /**
   * Set/get how far (mm) an outline point may be from the skin; points are
   * moved onto it. Default is 3.
   */
  vtkSetClampMacro(SkinTolerance, double, 0.0, 100.0);
  vtkGetMacro(SkinTolerance, double);
  ///@}

  /**
   * How far (mm) a point (RAS) is from the skin along the image gradient, or
   * VTK_DOUBLE_MAX if the skin is farther than reach (mm): for checking an
   * outline's control points before planning.
   */
  double GetDistanceToSkin(const double ras[3], double reach);

  /**
   * Build the shape and the mask, growing the bounding box until the
   * resection's reach lies inside it. Returns false with a message for bad
   * input, keeping the previous plan.
   */
  bool Plan();

  ///@{
  /**
   * The two stages of Plan on the current bounding box (for timing them):
   * BuildShape (outline on the skin, strips, box, two distance transforms,
   * shape and flood fill) and BuildMask (the depth of every voxel; needs
   * BuildShape first). They return false with a message for bad input.
   */
  bool BuildShape();
  bool BuildMask();
  ///@}

  /// Whether a complete plan (shape and mask) is available.
  bool HasPlan() const;

  /// What went wrong in the last call that returned false ("" after a success).
  const char* GetErrorMessage() const { return this->ErrorMessage.c_str(); }

  ///@{
  /**
   * The outline on the skin, the inner and outer strips (closed polylines,
   * RAS), the average outward normal of the outline (RAS, unit), its length
   * (mm) and the area it encloses seen along the average normal (mm^2).
   */
  void GetOutlineOnSkin(vtkPolyData* polyline) const;
  void GetInnerStrip(vtkPolyData* polyline) const;
  void GetOuterStrip(vtkPolyData* polyline) const;
  void GetAverageNormal(double normal[3]) const;
  double GetOutlineLength() const;
  double GetProjectedArea() const;
  ///@}

  /// The bounding box of the planning (anatomy voxel indices, inclusive).
  void GetBoxExtent(int extent[6]) const;

  /// Voxel classes in the box image of GetShapeImage (bits).
  enum ShapeClasses
  {
    InShape = 1,      ///< nearer the inner strip than the outer one
    SkinPatch = 2,    ///< the skin's first tissue voxels inside the outline
    FilledTissue = 4  ///< soft tissue reached by the flood fill
  };

  /**
   * The shape as an unsigned char image over the box (extent in anatomy
   * voxel indices, origin 0 and spacing 1: the anatomy's IJK to RAS places
   * it), each voxel a combination of ShapeClasses.
   */
  void GetShapeImage(vtkImageData* image) const;

  /**
   * The mask: the depth (mm) of every voxel of the box under the skin inside
   * the outline (negative above it), as a float image like GetShapeImage's.
   */
  void GetDepthImage(vtkImageData* image) const;

  /// Voxels reached by the flood fill, and the deepest of them (mm) within MaximumDepth.
  vtkIdType GetNumberOfFilledVoxels() const;

  /**
   * The resection at a depth of cut (mm) as vtkVolumeCutField::CutSampledRegion
   * takes it: distances (four float components over the part of the box the
   * region reaches: the wall, the depth minus the depth of cut, the height
   * above the skin minus a margin of two voxels, so that the skin is opened
   * cleanly, and the distance into bone, the CT's iso-surface at the top of
   * the soft-tissue range, so that the print the resection leaves on bone is
   * smooth) and keep (unsigned char: 1 for voxels never removed, bone and
   * tissue the fill did not reach). A field given as shieldSource
   * adds its shielded voxels to keep (for a preview field that should show
   * what the real carve will leave). False with a message for a depth that
   * is not positive or beyond MaximumDepth, or without a plan.
   */
  bool BuildRegion(double depth, vtkImageData* distances, vtkImageData* keep, vtkVolumeCutField* shieldSource = nullptr);

  /**
   * Carve the resection at a depth of cut into a cut field initialised on
   * the anatomy's grid, as one undo step (BuildRegion, then
   * CutSampledRegion). False with a message, nothing carved, for bad input.
   */
  bool Carve(vtkVolumeCutField* field, double depth, vtkVolumeCutField* shieldSource = nullptr);

  /**
   * The resected tissue at a depth of cut as an implicit function for
   * contouring: a float image over the region's part of the box, sampled
   * subdivision (1 or 2) times per voxel along each axis, negative inside
   * (between the skin and the depth of cut, inside the wall, outside the
   * voxels kept). Its origin and spacing are anatomy IJK coordinates, so the
   * anatomy's IJK to RAS (GetIJKToRAS) places a contour of it.
   */
  bool BuildResectedTissueFunction(double depth, int subdivision, vtkImageData* function);

  /// The anatomy's IJK to RAS as the planner uses it.
  void GetIJKToRAS(vtkMatrix4x4* matrix) const;

protected:
  vtkVolumeCutResectionPlanner();
  ~vtkVolumeCutResectionPlanner() override;

  bool Fail(const std::string& message) const;
  /// Reads the anatomy's grid; false with a message for an unusable one.
  bool UpdateGrid(const char* caller);

  vtkSmartPointer<vtkImageData> Anatomy;
  vtkSmartPointer<vtkMatrix4x4> IJKToRAS;
  vtkSmartPointer<vtkPoints> Outline;
  int NormalMode = LocalNormal;
  double SkinIsoValue = -500.0;
  double SoftTissueRange[2] = { -500.0, 250.0 };
  double StripOffset = 0.0;
  double MaximumDepth = 30.0;
  double SkinTolerance = 3.0;
  mutable std::string ErrorMessage;

private:
  vtkVolumeCutResectionPlanner(const vtkVolumeCutResectionPlanner&) = delete;
  void operator=(const vtkVolumeCutResectionPlanner&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
