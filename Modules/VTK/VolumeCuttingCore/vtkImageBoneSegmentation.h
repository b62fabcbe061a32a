// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkImageBoneSegmentation
 * @brief   Segment cortical and trabecular bone in a CT by region growing.
 *
 * CT preprocessing of a virtual bone surgery system (Missouri S&T, Computer
 * Aided Surgery 2007): optional Gaussian smoothing against noise, then region
 * growing with a first-in-first-out queue, so that the size of a region never
 * grows the call stack.
 *
 * Every voxel at or above CorticalThreshold seeds a region. Regions grow over
 * face-connected voxels at or above TrabecularThreshold. Grown voxels below
 * the cortical threshold are trabecular bone, except the cortex's boundary
 * (BoundaryIsCortical): the paper's bone model has a cortical boundary
 * around a trabecular interior, and where cortex meets air or soft tissue
 * the voxels the boundary passes through hold part cortex, part
 * surroundings (partial volume), so their values fall in the trabecular
 * range although they are cortex. Bright voxels that no cortical seed
 * reaches (calcifications, contrast, noise) are not bone: this connectivity
 * is what region growing adds to thresholding.
 *
 * The output is an unsigned char label image with the input's extent, origin,
 * spacing and direction: BackgroundLabel, CorticalLabel or TrabecularLabel.
 * Values that are not finite (NaN) are never bone.
 */

#ifndef vtkImageBoneSegmentation_h
#define vtkImageBoneSegmentation_h

#include "vtkImageAlgorithm.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

class VTK_VOLUMECUTTINGCORE_EXPORT vtkImageBoneSegmentation : public vtkImageAlgorithm
{
public:
  static vtkImageBoneSegmentation* New();
  vtkTypeMacro(vtkImageBoneSegmentation, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum Labels
  {
    BackgroundLabel = 0,
    CorticalLabel = 1,
    TrabecularLabel = 2
  };

  ///@{
  /**
   * Set/get the lowest value (HU) of cortical bone; such voxels seed regions.
   * Default is 700.
   */
  vtkSetMacro(CorticalThreshold, double);
  vtkGetMacro(CorticalThreshold, double);
  ///@}

  ///@{
  /**
   * Set/get the lowest value (HU) that regions grow into. Must not exceed the
   * cortical threshold. Default is 200.
   */
  vtkSetMacro(TrabecularThreshold, double);
  vtkGetMacro(TrabecularThreshold, double);
  ///@}

  ///@{
  /**
   * Set/get whether the partial-volume shell of the cortex is cortical:
   * grown voxels on the ramp (one or two voxels) from a cortical voxel out
   * to what is not bone, whatever their value. Default is true.
   */
  vtkSetMacro(BoundaryIsCortical, bool);
  vtkGetMacro(BoundaryIsCortical, bool);
  vtkBooleanMacro(BoundaryIsCortical, bool);
  ///@}

  ///@{
  /**
   * Set/get the standard deviation in millimetres of the Gaussian smoothing
   * applied before thresholding; 0 disables smoothing. Default is 0.
   */
  vtkSetClampMacro(SmoothingStandardDeviation, double, 0.0, 100.0);
  vtkGetMacro(SmoothingStandardDeviation, double);
  ///@}

  ///@{
  /**
   * Get the number of voxels of each label after the last update.
   */
  vtkGetMacro(NumberOfCorticalVoxels, vtkIdType);
  vtkGetMacro(NumberOfTrabecularVoxels, vtkIdType);
  ///@}

protected:
  vtkImageBoneSegmentation();
  ~vtkImageBoneSegmentation() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double CorticalThreshold = 700.0;
  double TrabecularThreshold = 200.0;
  double SmoothingStandardDeviation = 0.0;
  bool BoundaryIsCortical = true;
  vtkIdType NumberOfCorticalVoxels = 0;
  vtkIdType NumberOfTrabecularVoxels = 0;

private:
  vtkImageBoneSegmentation(const vtkImageBoneSegmentation&) = delete;
  void operator=(const vtkImageBoneSegmentation&) = delete;
};

#endif
