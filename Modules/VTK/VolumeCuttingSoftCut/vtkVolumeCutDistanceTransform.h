// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutDistanceTransform
 * @brief   Exact Euclidean distance transform that also says which site is nearest.
 *
 * For every voxel, the distance (mm) from its centre to the centre of the
 * nearest site voxel (a voxel whose first scalar component is not zero), on
 * grids with any spacing, and optionally the point id of that site (its
 * "feature"). SoftCut (Blache et al.) needs exact distances far from the
 * sites and on anisotropic grids, which rules out chamfer transforms; it
 * needs the nearest site too, to measure distances to the resection
 * outline's polylines and to the skin's sub-voxel surface instead of to
 * voxel centres.
 *
 * Separable and exact: one pass per axis, each the lower envelope of the
 * parabolas left by the previous passes (Felzenszwalb and Huttenlocher,
 * "Distance transforms of sampled functions", 2012; the same squared
 * distances as Saito's algorithm in vtkImageEuclideanDistance). Lines are
 * processed in tiles of neighbouring lines so that the passes along y and z
 * read whole cache lines, and tiles are spread over threads (vtkSMPTools).
 * Where two sites are equally near, which one is reported is unspecified.
 *
 * The output has the input's geometry and two point-data arrays: the float
 * scalars "Distance" and, when ComputeNearestSite is on, the vtkIdTypeArray
 * "NearestSite" (-1 where the image has no site, where the distance is
 * infinite).
 *
 * @sa vtkImageEuclideanDistance
 */

#ifndef vtkVolumeCutDistanceTransform_h
#define vtkVolumeCutDistanceTransform_h

#include "vtkImageAlgorithm.h"
#include "vtkVolumeCuttingSoftCutExport.h" // For export macro

class VTK_VOLUMECUTTINGSOFTCUT_EXPORT vtkVolumeCutDistanceTransform : public vtkImageAlgorithm
{
public:
  static vtkVolumeCutDistanceTransform* New();
  vtkTypeMacro(vtkVolumeCutDistanceTransform, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Set/get whether the output holds squared distances (mm^2) instead of
   * distances. Default is false.
   */
  vtkSetMacro(OutputSquaredDistance, bool);
  vtkGetMacro(OutputSquaredDistance, bool);
  vtkBooleanMacro(OutputSquaredDistance, bool);
  ///@}

  ///@{
  /**
   * Set/get whether the point id of each voxel's nearest site is written
   * (array "NearestSite"). Default is false.
   */
  vtkSetMacro(ComputeNearestSite, bool);
  vtkGetMacro(ComputeNearestSite, bool);
  vtkBooleanMacro(ComputeNearestSite, bool);
  ///@}

#ifndef __VTK_WRAP__
  /**
   * The transform on raw arrays of dimensions[0] * dimensions[1] *
   * dimensions[2] voxels, x fastest: sites (nonzero: a site) in,
   * squaredDistances (mm^2, +infinity without any site) and, unless nullptr,
   * nearestSites (linear index, -1 without any site) out. squaredDistances is
   * the working array of the passes, so it is required even where only the
   * nearest sites are wanted.
   */
  static void Compute(const int dimensions[3], const double spacing[3], const unsigned char* sites, float* squaredDistances, int* nearestSites);
#endif

protected:
  vtkVolumeCutDistanceTransform();
  ~vtkVolumeCutDistanceTransform() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  bool OutputSquaredDistance = false;
  bool ComputeNearestSite = false;

private:
  vtkVolumeCutDistanceTransform(const vtkVolumeCutDistanceTransform&) = delete;
  void operator=(const vtkVolumeCutDistanceTransform&) = delete;
};

#endif
