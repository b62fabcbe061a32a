// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutLabelSmoothing
 * @brief   Fractions of segments drawn from binary labelmaps: shape-based interpolation between slices.
 *
 * A segment known only as whole voxels (a binary labelmap) drawn by its own
 * shape is drawn at its smoothed surface, vtkVolumeCutLabelSurface's (the
 * nerve monitor measures to the same one): the fraction is a linear ramp of
 * the surface's levels, 0.5 on it, so that the trilinear interpolation of
 * fractions interpolates the levels and its 0.5 level set is that surface.
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
