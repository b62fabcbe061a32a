// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCutting (not installed, not wrapped); exported because the
// renderer's label smoothing (VolumeCuttingRendering) and the shield
// (vtkVolumeCutProtection) build the same surface from it.
/**
 * @class   vtkVolumeCutSliceDistance
 * @brief   Smoothed signed distance to a binary outline within one slice.
 *
 * A segment known only as whole voxels has voxel stairs for a surface. Both
 * the renderer (vtkVolumeCutLabelSmoothing) and the shield that keeps tools
 * out of protected segments replace them by one smooth surface: in each
 * slice across the axis of largest spacing, the signed distance (mm) of
 * every pixel to the segment's outline, halfway between pixel centres (two
 * exact 1D passes of Felzenszwalb and Huttenlocher's lower envelope of
 * parabolas), bounded, and smoothed in the slice by a Gaussian against the
 * pixels' stairs; the surface is its zero, interpolated between slices
 * (shape-based interpolation, Raya and Udupa 1990). One implementation, so
 * that the wall a burr leaves against a protected structure is the surface
 * drawn for it.
 */
#ifndef vtkVolumeCutSliceDistance_h
#define vtkVolumeCutSliceDistance_h

#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <cstdint> // For uint8_t
#include <vector>  // For the kernel and the working memory

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutSliceDistance
{
public:
  /// Working memory kept between slices (one per thread).
  struct Scratch
  {
    std::vector<uint8_t> Outside;
    std::vector<double> ToInside;
    std::vector<double> Line;
    std::vector<double> Result;
    std::vector<double> Envelope;
    std::vector<int> Parabolas;
    std::vector<double> Convolved;
  };

  /// A normalised Gaussian of sigma pixels over +-ceil(3 sigma) (at least +-1) pixels.
  static std::vector<double> GaussianKernel(double sigma);

  /**
   * For a nu x nv slice (u fastest) of pixels su x sv mm with at least one
   * pixel inside: into distance, each pixel's signed distance (mm, negative
   * inside) to the outline halfway between inside and outside pixel centres,
   * bounded to +-bound, then convolved with kernel along u and v (edges
   * clamped; an empty kernel leaves it unsmoothed).
   */
  static void SmoothedSignedDistance(const uint8_t* inside, int nu, int nv, double su, double sv, double bound, const std::vector<double>& kernel,
    double* distance, Scratch& scratch);
  /// The same, exact only within region (first and last u, first and last v) and computed only as far as that needs.
  static void SmoothedSignedDistance(const uint8_t* inside, int nu, int nv, double su, double sv, double bound, const std::vector<double>& kernel,
    const int region[4], double* distance, Scratch& scratch);

  /// Squared distance (mm^2) of each pixel of a nu x nv slice to the nearest pixel where feature is non-zero (1e20 where there is none).
  static void SquaredDistance2D(const uint8_t* feature, int nu, int nv, double su, double sv, double* squared, Scratch& scratch);
  /// The same, exact only in the columns (u) firstColumn..lastColumn.
  static void SquaredDistance2D(
    const uint8_t* feature, int nu, int nv, double su, double sv, int firstColumn, int lastColumn, double* squared, Scratch& scratch);

private:
  vtkVolumeCutSliceDistance() = delete;
};

#endif
