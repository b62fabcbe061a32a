/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingSegmentLayers.h"

// VolumeCutting includes
#include "vtkVolumeCutRemovedVoxels.h"

// SegmentationCore includes
#include <vtkOrientedImageData.h>
#include <vtkOrientedImageDataResample.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>

// STD includes
#include <cmath>
#include <sstream>

vtkStandardNewMacro(vtkSlicerVolumeCuttingSegmentLayers);

namespace
{
/// Grids agree when every voxel corner lies within this fraction of a voxel.
constexpr double GridTolerance = 1e-3;
} // namespace

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingSegmentLayers::vtkSlicerVolumeCuttingSegmentLayers() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingSegmentLayers::~vtkSlicerVolumeCuttingSegmentLayers() = default;

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSegmentLayers::GetLatticeMap(vtkMatrix4x4* imageToWorld, vtkMatrix4x4* anatomyIJKToRAS, int permutation[3][3], int offset[3])
{
  if (!imageToWorld || !anatomyIJKToRAS)
  {
    return false;
  }
  // Anatomy index of each image index: a = M i + m; one lattice when M is a
  // signed permutation and m whole numbers (to a thousandth of a voxel).
  vtkNew<vtkMatrix4x4> rasToIJK;
  vtkMatrix4x4::Invert(anatomyIJKToRAS, rasToIJK);
  vtkNew<vtkMatrix4x4> map;
  vtkMatrix4x4::Multiply4x4(rasToIJK, imageToWorld, map);
  for (int row = 0; row < 3; ++row)
  {
    int ones = 0;
    for (int column = 0; column < 4; ++column)
    {
      const double value = map->GetElement(row, column);
      const double nearest = std::round(value);
      if (!(std::abs(value - nearest) <= GridTolerance) || (column < 3 && std::abs(nearest) > 1.0))
      {
        return false;
      }
      if (column < 3)
      {
        permutation[row][column] = static_cast<int>(nearest);
        ones += nearest != 0.0;
      }
      else
      {
        offset[row] = static_cast<int>(nearest);
      }
    }
    if (ones != 1)
    {
      return false;
    }
  }
  return true;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSegmentLayers::GetOffsetOnGrid(vtkMatrix4x4* imageToWorld, vtkMatrix4x4* anatomyIJKToRAS, int offset[3])
{
  int permutation[3][3];
  if (!GetLatticeMap(imageToWorld, anatomyIJKToRAS, permutation, offset))
  {
    return false;
  }
  for (int row = 0; row < 3; ++row)
  {
    if (permutation[row][row] != 1)
    {
      return false; // the same voxels in another index order
    }
  }
  return true;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSegmentLayers::Update(vtkSegmentation* segmentation, const int anatomyDimensions[3], vtkMatrix4x4* anatomyIJKToRAS)
{
  if (!segmentation || !anatomyDimensions || !anatomyIJKToRAS)
  {
    vtkErrorMacro("Update: a segmentation and an anatomy grid are required");
    return false;
  }
  std::ostringstream gridKey;
  gridKey.precision(17);
  gridKey << anatomyDimensions[0] << " " << anatomyDimensions[1] << " " << anatomyDimensions[2];
  for (int element = 0; element < 12; ++element)
  {
    gridKey << " " << anatomyIJKToRAS->GetElement(element / 4, element % 4);
  }
  const std::string binary = vtkSegmentationConverter::GetBinaryLabelmapRepresentationName();
  if (segmentation->GetNumberOfSegments() > 0 && !segmentation->ContainsRepresentation(binary))
  {
    segmentation->CreateRepresentation(binary);
  }
  if (this->Segmentation == segmentation && this->SegmentationTime == segmentation->GetMTime() && this->GridKey == gridKey.str())
  {
    return true;
  }
  this->Layers.clear();
  this->Segments.clear();
  this->ResampledSegmentIDs.clear();
  this->Segmentation = segmentation;
  this->SegmentationTime = segmentation->GetMTime();
  this->GridKey = gridKey.str();

  vtkNew<vtkOrientedImageData> anatomyGeometry;
  anatomyGeometry->SetImageToWorldMatrix(anatomyIJKToRAS);
  anatomyGeometry->SetExtent(0, anatomyDimensions[0] - 1, 0, anatomyDimensions[1] - 1, 0, anatomyDimensions[2] - 1);
  const int layerCount = segmentation->GetNumberOfLayers(binary);
  for (int index = 0; index < layerCount; ++index)
  {
    vtkOrientedImageData* layer = vtkOrientedImageData::SafeDownCast(segmentation->GetLayerDataObject(index, binary));
    if (!layer || !layer->GetPointData()->GetScalars())
    {
      continue;
    }
    const std::vector<std::string> segmentIds = segmentation->GetSegmentIDsForDataObject(layer, binary);
    vtkNew<vtkMatrix4x4> layerToWorld;
    layer->GetImageToWorldMatrix(layerToWorld);
    int offset[3];
    auto onGrid = vtkSmartPointer<vtkImageData>::New();
    if (GetOffsetOnGrid(layerToWorld, anatomyIJKToRAS, offset))
    {
      // The layer itself, its extent moved into anatomy IJK: no copy.
      int extent[6];
      layer->GetExtent(extent);
      onGrid->ShallowCopy(layer);
      onGrid->SetExtent(extent[0] + offset[0], extent[1] + offset[0], extent[2] + offset[1], extent[3] + offset[1], extent[4] + offset[2],
        extent[5] + offset[2]);
    }
    else
    {
      vtkNew<vtkOrientedImageData> resampled;
      if (!vtkOrientedImageDataResample::ResampleOrientedImageToReferenceOrientedImage(layer, anatomyGeometry, resampled, false))
      {
        vtkErrorMacro("Update: a labelmap layer of the segmentation could not be resampled onto the anatomy's grid");
        continue;
      }
      onGrid->ShallowCopy(resampled);
      // A layer on the same voxels in another index order is copied exactly.
      int permutation[3][3];
      if (!GetLatticeMap(layerToWorld, anatomyIJKToRAS, permutation, offset))
      {
        this->ResampledSegmentIDs.insert(this->ResampledSegmentIDs.end(), segmentIds.begin(), segmentIds.end());
      }
    }
    onGrid->SetOrigin(0.0, 0.0, 0.0);
    onGrid->SetSpacing(1.0, 1.0, 1.0);
    const int layerIndex = static_cast<int>(this->Layers.size());
    this->Layers.push_back(onGrid);
    for (const std::string& segmentId : segmentIds)
    {
      vtkSegment* segment = segmentation->GetSegment(segmentId);
      if (segment)
      {
        this->Segments[segmentId] = Placement{ layerIndex, segment->GetLabelValue() };
      }
    }
  }
  return true;
}

//----------------------------------------------------------------------------
vtkImageData* vtkSlicerVolumeCuttingSegmentLayers::GetLayer(int index) const
{
  return index >= 0 && index < this->GetNumberOfLayers() ? this->Layers[index].GetPointer() : nullptr;
}

//----------------------------------------------------------------------------
int vtkSlicerVolumeCuttingSegmentLayers::GetSegmentLayer(const std::string& segmentId, int& labelValue) const
{
  auto found = this->Segments.find(segmentId);
  if (found == this->Segments.end())
  {
    labelValue = 0;
    return -1;
  }
  labelValue = found->second.LabelValue;
  return found->second.Layer;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSegmentLayers::IsInSegment(int layer, int labelValue, int i, int j, int k) const
{
  vtkImageData* image = this->GetLayer(layer);
  if (!image)
  {
    return false;
  }
  const int* extent = image->GetExtent();
  if (i < extent[0] || i > extent[1] || j < extent[2] || j > extent[3] || k < extent[4] || k > extent[5])
  {
    return false;
  }
  return static_cast<int>(image->GetScalarComponentAsDouble(i, j, k, 0)) == labelValue;
}

//----------------------------------------------------------------------------
std::map<std::string, double> vtkSlicerVolumeCuttingSegmentLayers::SumRemovedFractions(
  vtkVolumeCutRemovedVoxels* voxels, const int anatomyDimensions[3], const std::vector<std::string>& segmentIds) const
{
  std::map<std::string, double> sums;
  if (!voxels)
  {
    return sums;
  }
  // Which segments each (layer, value) stands for.
  std::vector<std::map<int, std::vector<std::string>>> byValue(static_cast<size_t>(this->GetNumberOfLayers()));
  for (const std::string& segmentId : segmentIds)
  {
    int value = 0;
    const int layer = this->GetSegmentLayer(segmentId, value);
    if (layer >= 0)
    {
      byValue[layer][value].push_back(segmentId);
      sums[segmentId] = 0.0;
    }
  }
  const int* dims = anatomyDimensions;
  voxels->ForEachVoxel([&](vtkIdType id, float fraction) {
    const int i = static_cast<int>(id % dims[0]);
    const int j = static_cast<int>((id / dims[0]) % dims[1]);
    const int k = static_cast<int>(id / (static_cast<vtkIdType>(dims[0]) * dims[1]));
    for (int layer = 0; layer < this->GetNumberOfLayers(); ++layer)
    {
      if (byValue[layer].empty())
      {
        continue;
      }
      vtkImageData* image = this->GetLayer(layer);
      const int* extent = image->GetExtent();
      if (i < extent[0] || i > extent[1] || j < extent[2] || j > extent[3] || k < extent[4] || k > extent[5])
      {
        continue;
      }
      auto found = byValue[layer].find(static_cast<int>(image->GetScalarComponentAsDouble(i, j, k, 0)));
      if (found != byValue[layer].end())
      {
        for (const std::string& segmentId : found->second)
        {
          sums[segmentId] += fraction;
        }
      }
    }
  });
  return sums;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSegmentLayers::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Layers: " << this->Layers.size() << "\n";
  os << indent << "Segments: " << this->Segments.size() << "\n";
  os << indent << "ResampledSegments: " << this->ResampledSegmentIDs.size() << "\n";
}
