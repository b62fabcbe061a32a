// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutBoneAhead
 * @brief   The thickness of the bone left ahead of the tool, measured as the renderer's thin-bone tint measures it.
 *
 * Surgeons hear a burr's pitch rise as the bone ahead of it thins, before it
 * breaks through (seed 003); the renderer shows the same thing by tinting
 * thin walls red (vtkVolumeCutThinBoneShader, inside the ray caster, with no
 * readout per stroke). This query measures that wall along a direction
 * (the tool's axis, the view direction of the web application) from a start
 * point (the burr's tip): it marches in quarter-voxel steps to where bone
 * begins (within Range), then on to where it ends, and finds each crossing
 * by halving the last step six times (1/256 of a voxel), as the shader does.
 *
 * Bone is where the trilinearly interpolated bone mask is at least one half
 * (the renderer's rule for segments drawn by their shape) and the cut field,
 * if one is set, has not removed it (its signed distance is not negative).
 * The march reads the field while a writer cuts, as the renderer does.
 *
 * Measure returns the thickness in mm: +inf when no bone begins within Range
 * ahead (nothing thins), MaximumThickness when the wall is at least that
 * thick or goes on beyond the scan, NaN (and an error) for a zero direction
 * or before SetBone.
 */

#ifndef vtkVolumeCutBoneAhead_h
#define vtkVolumeCutBoneAhead_h

#include "vtkObject.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro
#include "vtkWeakPointer.h"             // For the cut field

#include <cstdint> // For the mask
#include <vector>  // For the mask

class vtkImageData;
class vtkMatrix4x4;
class vtkVolumeCutField;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutBoneAhead : public vtkObject
{
public:
  static vtkVolumeCutBoneAhead* New();
  vtkTypeMacro(vtkVolumeCutBoneAhead, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * The bone: the non-zero voxels of labels (one integer or real component;
   * its extent says which voxels of the grid it covers, its origin and
   * spacing are not read), placed in RAS by ijkToRAS. Copied. False (and an
   * error, the previous bone kept) for a missing or singular matrix, an
   * image without one component, or no bone voxel.
   */
  bool SetBone(vtkImageData* labels, vtkMatrix4x4* ijkToRAS);
  /// Whether SetBone succeeded.
  bool HasBone() const { return !this->Mask.empty(); }

  /// The cut field whose removed region is no longer bone (not owned; none: the bone as labelled).
  void SetCutField(vtkVolumeCutField* field);
  vtkVolumeCutField* GetCutField();

  /// How far (mm) ahead of the start point bone is looked for. Default 4.
  vtkSetClampMacro(Range, double, 0.0, 1.0e3);
  vtkGetMacro(Range, double);
  /// The thickest wall (mm) measured; a thicker one reads as this. Default 4.
  vtkSetClampMacro(MaximumThickness, double, 0.0, 1.0e3);
  vtkGetMacro(MaximumThickness, double);

  /// Thickness (mm) of the bone ahead of start (RAS) along direction (RAS, any length).
  double Measure(const double start[3], const double direction[3]) const;
  /// Distance (mm) from the start point to where the bone began, in the last Measure (+inf if none).
  double GetLastGap() const { return this->LastGap; }

  /// Whether the point (RAS) is bone.
  bool IsBone(const double ras[3]) const;

protected:
  vtkVolumeCutBoneAhead();
  ~vtkVolumeCutBoneAhead() override;

private:
  vtkVolumeCutBoneAhead(const vtkVolumeCutBoneAhead&) = delete;
  void operator=(const vtkVolumeCutBoneAhead&) = delete;

  /// A march's line: start and direction (per mm) in RAS and in the mask's continuous index.
  struct Line
  {
    double Start[3];
    double Direction[3];
    double StartIndex[3];
    double DirectionIndex[3];
  };
  /// Bone at a continuous index of the mask (and its RAS point, for the cut field).
  bool BoneAt(const double index[3], const double ras[3]) const;
  /// Whether the point at t (mm) along the line is bone; outside says the point left the grid.
  bool BoneAlong(const Line& line, double t, bool& outside) const;
  /// Where bone begins or ends between t0 and t1 (bone at t1 iff boneAtT1), by halving.
  double Crossing(const Line& line, double t0, double t1, bool boneAtT1) const;

  std::vector<uint8_t> Mask;
  int Extent[6] = { 0, -1, 0, -1, 0, -1 };
  double IJKToRAS[16];
  double RASToIJK[16];
  vtkWeakPointer<vtkVolumeCutField> CutField;
  double Range = 4.0;
  double MaximumThickness = 4.0;
  // What the last Measure found before the wall (for the thread that owns the query).
  mutable double LastGap = 0.0;
};

#endif
