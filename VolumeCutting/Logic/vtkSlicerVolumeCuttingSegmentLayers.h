/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkSlicerVolumeCuttingSegmentLayers_h
#define vtkSlicerVolumeCuttingSegmentLayers_h

// VTK includes
#include <vtkObject.h>
#include <vtkSmartPointer.h>
#include <vtkWeakPointer.h>

// STD includes
#include <map>
#include <string>
#include <vector>

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

class vtkImageData;
class vtkMatrix4x4;
class vtkSegmentation;
class vtkVolumeCutRemovedVoxels;

/// \brief A segmentation's labelmap layers on an anatomy's voxel grid, without copies.
///
/// Slicer stores segments as binary labelmap layers that several segments
/// share with different label values. On a patient-scale scan a layer is
/// tens of megabytes: the cut session reads the layers where it needs them
/// (the shield brick by brick, per-segment volumes voxel by voxel) instead of
/// copying each segment into a mask of the whole volume. A layer already on
/// the anatomy's grid (same axes and spacing, origin a whole number of voxels
/// away, within 1e-3 voxel) is used as it is; any other is resampled onto the
/// grid once, nearest neighbour, and kept until the segmentation changes.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingSegmentLayers : public vtkObject
{
public:
  static vtkSlicerVolumeCuttingSegmentLayers* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingSegmentLayers, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Follow a segmentation on an anatomy grid (dimensions and IJK-to-RAS).
  /// Cheap when neither changed since the last call. Segments without a
  /// binary labelmap get one (Slicer's conversion). Returns false (and an
  /// error) without a segmentation or grid.
  bool Update(vtkSegmentation* segmentation, const int anatomyDimensions[3], vtkMatrix4x4* anatomyIJKToRAS);

  /// Number of layer images on the anatomy grid.
  int GetNumberOfLayers() const { return static_cast<int>(this->Layers.size()); }
  /// Layer image on the anatomy grid: its extent is in anatomy IJK; origin,
  /// spacing and direction are not meaningful.
  vtkImageData* GetLayer(int index) const;

  /// The layer holding a segment and the segment's value in it; -1 if the
  /// segment is unknown or has no labelmap.
  int GetSegmentLayer(const std::string& segmentId, int& labelValue) const;

  /// Segments whose layer was resampled (not on the anatomy's voxels).
  const std::vector<std::string>& GetResampledSegmentIDs() const { return this->ResampledSegmentIDs; }

  /// Whether a segment's layer holds its value at anatomy voxel (i, j, k).
  bool IsInSegment(int layer, int labelValue, int i, int j, int k) const;

#ifndef __VTK_WRAP__
  /// The removed fractions of a cut's voxels summed per segment, in voxels
  /// (times the voxel volume, mm^3): one read per layer and removed voxel,
  /// whatever the number of segments. Segments without a labelmap are left
  /// out of the result; the others start at 0.
  std::map<std::string, double> SumRemovedFractions(vtkVolumeCutRemovedVoxels* voxels, const int anatomyDimensions[3],
                                                    const std::vector<std::string>& segmentIds) const;
#endif

  /// The grid offset (anatomy IJK of the image's voxel 0) of an image with the
  /// given image-to-world matrix, when it lies on the anatomy grid.
  static bool GetOffsetOnGrid(vtkMatrix4x4* imageToWorld, vtkMatrix4x4* anatomyIJKToRAS, int offset[3]);

  /// Whether an image lies on the anatomy's voxels in any index order: the
  /// signed permutation and offset taking its indices to the anatomy's.
  static bool GetLatticeMap(vtkMatrix4x4* imageToWorld, vtkMatrix4x4* anatomyIJKToRAS, int permutation[3][3], int offset[3]);

protected:
  vtkSlicerVolumeCuttingSegmentLayers();
  ~vtkSlicerVolumeCuttingSegmentLayers() override;

  struct Placement
  {
    int Layer = -1;
    int LabelValue = 0;
  };
  std::vector<vtkSmartPointer<vtkImageData>> Layers;
  std::map<std::string, Placement> Segments;
  std::vector<std::string> ResampledSegmentIDs;

  vtkWeakPointer<vtkSegmentation> Segmentation;
  vtkMTimeType SegmentationTime = 0;
  std::string GridKey;

private:
  vtkSlicerVolumeCuttingSegmentLayers(const vtkSlicerVolumeCuttingSegmentLayers&) = delete;
  void operator=(const vtkSlicerVolumeCuttingSegmentLayers&) = delete;
};

#endif
