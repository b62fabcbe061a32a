// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutLabelSurface
 * @brief   The smoothed surface of a segment known only as whole voxels (a binary labelmap).
 *
 * One definition of where such a segment's surface is, shared by the
 * renderer (which draws it, vtkVolumeCutRayCaster::SetLabelSmoothing) and
 * the nerve monitor (which measures the distance to it), so that the
 * monitor reads contact exactly where the view shows it.
 *
 * The voxels' stairs, and on a CT with thick slices (2.5 mm under 0.7 mm
 * pixels) terraces one slice high, are not the structure's surface. Each
 * slice across the axis of largest spacing gets its signed distance to the
 * segment's outline (two-pass exact Euclidean distance transform, in mm,
 * the outline halfway between pixel centres), smoothed in the slice by a
 * Gaussian of the given width against the pixels' stairs and clamped to
 * plus or minus the ramp (two slice spacings). The surface is the zero set
 * of the trilinear interpolation of these levels: between slices the
 * outline moves smoothly (shape-based interpolation, Raya and Udupa 1990),
 * without the shrinking of smoothed closed surfaces. Beyond the first and
 * last slices holding the segment, the levels are extrapolated from the last
 * two slices, so that a tapering end (the pole of a ball) closes where its
 * outlines shrink to, but no further than halfway to the next slice over the
 * last outline, where a blunt end closes as the binary indicator does.
 *
 * Static functions on raw arrays; callers spread ComputeSlices over threads.
 */
#ifndef vtkVolumeCutLabelSurface_h
#define vtkVolumeCutLabelSurface_h

#include "vtkObject.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro
#include "vtkWrappingHints.h"           // For VTK_WRAPEXCLUDE

#include <cstdint> // For uint16_t
#include <vector>  // For the levels

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutLabelSurface : public vtkObject
{
public:
  static vtkVolumeCutLabelSurface* New();
  vtkTypeMacro(vtkVolumeCutLabelSurface, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Levels of one segment on a box of the label map's voxels: signed
   * distance (mm, negative inside) clamped to plus or minus Ramp, x fastest
   * over the box (inclusive voxel bounds); +Ramp (outside) beyond it.
   */
  struct VTK_WRAPEXCLUDE Levels
  {
    int Box[6] = { 0, -1, 0, -1, 0, -1 };
    int SliceAxis = 2;
    double Ramp = 0.0;
    std::vector<float> Values;
  };

  /**
   * Each label's bounding box (inclusive voxel bounds; empty, max < min,
   * where the label does not occur) in one pass over the label map of
   * dimensions voxels, x fastest.
   */
  VTK_WRAPEXCLUDE static void ComputeLabelBoxes(const uint16_t* labelMap, const int dimensions[3], const std::vector<int>& labels,
    std::vector<std::vector<int>>& boxes);

  /**
   * Prepare levels for label whose bounding box is labelBox: their box
   * (labelBox widened by what the ramp and the Gaussian of sigma pixels
   * reach in the slices, and by the extrapolated slice on each end, within
   * the label map), slice axis and ramp, values set to +Ramp. False for an
   * empty labelBox or a negative sigma.
   */
  VTK_WRAPEXCLUDE static bool Initialize(const int dimensions[3], const double spacing[3], const int labelBox[6], double sigma, Levels& levels);

  /// Number of slices (along SliceAxis) of the label's own box that ComputeSlices fills.
  VTK_WRAPEXCLUDE static int GetNumberOfSlices(const int labelBox[6], const Levels& levels);

  /**
   * Fill the slices [begin, end) of the label's own box (0: its first
   * slice). Slices do not share memory: threads may fill disjoint ranges.
   */
  VTK_WRAPEXCLUDE static void ComputeSlices(const uint16_t* labelMap, const int dimensions[3], const double spacing[3], int label,
    const int labelBox[6], double sigma, int begin, int end, Levels& levels);

  /// After every slice is filled: the levels beyond the first and last slices of the label (see above).
  VTK_WRAPEXCLUDE static void ExtrapolateEnds(const int labelBox[6], Levels& levels);

protected:
  vtkVolumeCutLabelSurface() = default;
  ~vtkVolumeCutLabelSurface() override = default;

private:
  vtkVolumeCutLabelSurface(const vtkVolumeCutLabelSurface&) = delete;
  void operator=(const vtkVolumeCutLabelSurface&) = delete;
};

#endif
