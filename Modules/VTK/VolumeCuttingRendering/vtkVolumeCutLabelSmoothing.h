// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutLabelSmoothing
 * @brief   Fractions of segments drawn from binary labelmaps: shape-based interpolation between slices.
 *
 * A segment known only as whole voxels (a binary labelmap) drawn by its own
 * shape shows the voxels' stairs at its indicator's 0.5 level, and on a CT
 * with thick slices (2.5 mm under 0.7 mm pixels) terraces one slice high:
 * the indicator, interpolated between a slice inside and one outside, puts
 * the surface halfway between them wherever the true surface is. Here each
 * slice (across the axis of largest spacing) gets its signed distance to
 * the segment's outline (two-pass exact Euclidean distance transform, in
 * mm), smoothed in the slice by a Gaussian of the given width against the
 * pixels' stairs; the fraction is a linear ramp of that distance, 0.5 on
 * the outline, so that the trilinear interpolation between slices
 * interpolates the distance: the outline moves smoothly from one slice to
 * the next (shape-based interpolation, Raya and Udupa 1990) and the
 * surface is as smooth as Slicer's smoothed closed surfaces, without their
 * shrinking.
 */
#ifndef vtkVolumeCutLabelSmoothing_h
#define vtkVolumeCutLabelSmoothing_h

#include "vtkVolumeCutRayScene.h"

#include <cstdint>
#include <vector>

class vtkVolumeCutLabelSmoothing
{
public:
  /**
   * For each of \a labels, the fraction volume (0..1 on the whole grid of
   * \a dims voxels of \a spacing mm, 0 beyond the label's box widened by the
   * ramp) described above, with an in-slice Gaussian of \a sigma voxels;
   * appended to \a fractions.
   */
  static void Smooth(const std::vector<uint16_t>& labelMap, const int dims[3], const double spacing[3], const std::vector<int>& labels,
    double sigma, int maximumThreads, std::vector<vtkVolumeCutRayScene::FractionVolume>& fractions);
};

#endif
