/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkSlicerVolumeCuttingExporter_h
#define vtkSlicerVolumeCuttingExporter_h

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

// VTK includes
#include <vtkObject.h>

// STD includes
#include <string>

class vtkImageData;
class vtkMRMLModelNode;
class vtkMRMLScalarVolumeNode;
class vtkMRMLScene;
class vtkMRMLSegmentationNode;
class vtkMRMLVolumeCutNode;
class vtkVolumeCutField;
class vtkVolumeCutRemovedVoxels;

/// \brief Adds a cut's results to the scene as ordinary Slicer nodes.
///
/// The removed region becomes a segmentation, a model of its surface, a
/// fractional volume or a drilled copy of the CT, on the anatomy's voxel
/// grid, so that Slicer's own storage and tools save and measure them
/// (segmentation and STL export, volume statistics). The module logic hands
/// in the cut's up-to-date field, removed voxels and removed fraction.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingExporter : public vtkObject
{
public:
  static vtkSlicerVolumeCuttingExporter* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingExporter, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// A segmentation with one segment "Removed": the anatomy voxels at least
  /// half removed (binary labelmap), \a fraction being the removed fraction
  /// of each anatomy voxel.
  static vtkMRMLSegmentationNode* AddRemovedRegionSegmentation(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkImageData* fraction,
                                                               const char* name);

  /// A model of the removed region's closed boundary, contoured by the field at sub-voxel resolution.
  static vtkMRMLModelNode* AddRemovedSurfaceModel(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field, const char* name);

  /// A float volume holding a copy of \a fraction on the anatomy's grid.
  static vtkMRMLScalarVolumeNode* AddRemovedFractionVolume(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkImageData* fraction,
                                                           const char* name);

  /// A copy of the anatomy with each removed voxel blended towards \a fillValue by its removed fraction.
  static vtkMRMLScalarVolumeNode* AddDrilledVolume(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutRemovedVoxels* voxels,
                                                   double fillValue, const char* name);

protected:
  vtkSlicerVolumeCuttingExporter();
  ~vtkSlicerVolumeCuttingExporter() override;

  /// Add a scalar volume holding \a image on the anatomy's voxel grid.
  static vtkMRMLScalarVolumeNode* AddVolumeOnAnatomyGrid(vtkMRMLScene* scene, vtkMRMLScalarVolumeNode* anatomy, vtkImageData* image,
                                                         const std::string& name);

private:
  vtkSlicerVolumeCuttingExporter(const vtkSlicerVolumeCuttingExporter&) = delete;
  void operator=(const vtkSlicerVolumeCuttingExporter&) = delete;
};

#endif
