/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkSlicerVolumeCuttingSegmentImages_h
#define vtkSlicerVolumeCuttingSegmentImages_h

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

// VTK includes
#include <vtkObject.h>

// STD includes
#include <string>
#include <vector>

class vtkImageData;
class vtkMRMLScalarVolumeNode;
class vtkMRMLSegmentationNode;
class vtkOrientedImageData;

/// \brief Segments as whole images on the anatomy's voxel grid.
///
/// The cut rendering colours each voxel by the segment it belongs to, and
/// blends fractional segments by their fraction: both read one image on the
/// anatomy's voxels (IJK geometry), whatever grid the segmentation is
/// stored on. vtkSlicerVolumeCuttingSegmentLayers reads the segmentation's
/// own layers instead where only some voxels are needed.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingSegmentImages : public vtkObject
{
public:
  static vtkSlicerVolumeCuttingSegmentImages* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingSegmentImages, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The anatomy's voxel grid as an oriented image (geometry only, no voxels).
  static void GetAnatomyGeometry(vtkMRMLScalarVolumeNode* anatomy, vtkOrientedImageData* geometry);

  /// Label map of the given segments on the anatomy's voxel grid (unsigned
  /// short, IJK geometry: label k + 1 for segmentIds[k], later segments win
  /// where they overlap). Returns the IDs that could not be rasterised (all
  /// of them without an anatomy with voxels or an output image).
  static std::vector<std::string> CreateLabelMap(vtkMRMLScalarVolumeNode* anatomy, vtkMRMLSegmentationNode* segmentation,
                                                 const std::vector<std::string>& segmentIds, vtkImageData* labels);

  /// A text that changes when the labels CreateLabelMap would give for these
  /// segments change: the anatomy's grid by its values and each segment's
  /// binary labels by their own modification time (the segmentation's is
  /// bumped by more than a change of voxels: a colour, a name, a tint).
  static std::string DescribeLabelSource(vtkMRMLScalarVolumeNode* anatomy, vtkMRMLSegmentationNode* segmentation,
                                         const std::vector<std::string>& segmentIds);

  /// The fraction (0..1 float, IJK geometry) of each anatomy voxel inside a
  /// segment that has a fractional labelmap representation, resampled
  /// linearly. Returns false (nothing written) when the segment has none.
  static bool CreateFraction(vtkMRMLScalarVolumeNode* anatomy, vtkMRMLSegmentationNode* segmentation, const std::string& segmentId,
                             vtkImageData* fraction);

protected:
  vtkSlicerVolumeCuttingSegmentImages();
  ~vtkSlicerVolumeCuttingSegmentImages() override;

private:
  vtkSlicerVolumeCuttingSegmentImages(const vtkSlicerVolumeCuttingSegmentImages&) = delete;
  void operator=(const vtkSlicerVolumeCuttingSegmentImages&) = delete;
};

#endif
