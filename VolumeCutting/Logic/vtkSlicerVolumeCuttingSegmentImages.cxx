/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingSegmentImages.h"

// MRML includes
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkOrientedImageData.h>
#include <vtkOrientedImageDataResample.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>

// VTK includes
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>

// STD includes
#include <algorithm>
#include <cmath>
#include <sstream>

namespace
{
// Whether image's voxel (i, j, k) is the anatomy's voxel (i, j, k): the same
// image-to-world matrix, to a small fraction of a voxel.
bool IsOnGrid(vtkOrientedImageData* image, vtkOrientedImageData* anatomyGeometry)
{
  vtkNew<vtkMatrix4x4> imageToWorld;
  vtkNew<vtkMatrix4x4> anatomyToWorld;
  image->GetImageToWorldMatrix(imageToWorld);
  anatomyGeometry->GetImageToWorldMatrix(anatomyToWorld);
  double spacing[3];
  anatomyGeometry->GetSpacing(spacing);
  const double tolerance = 1e-3 * std::min({ spacing[0], spacing[1], spacing[2] });
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      if (std::abs(imageToWorld->GetElement(row, column) - anatomyToWorld->GetElement(row, column)) > tolerance)
      {
        return false;
      }
    }
  }
  return true;
}

template <typename T>
void CopyVoxelsOfValueTyped(const T* voxels, const int sourceExtent[6], int value, unsigned short label, vtkImageData* labels)
{
  const int* dims = labels->GetDimensions();
  unsigned short* labelVoxels = static_cast<unsigned short*>(labels->GetScalarPointer());
  const vtkIdType rowLength = sourceExtent[1] - sourceExtent[0] + 1;
  const vtkIdType sliceLength = rowLength * (sourceExtent[3] - sourceExtent[2] + 1);
  for (int k = std::max(sourceExtent[4], 0); k <= std::min(sourceExtent[5], dims[2] - 1); ++k)
  {
    for (int j = std::max(sourceExtent[2], 0); j <= std::min(sourceExtent[3], dims[1] - 1); ++j)
    {
      const T* row = voxels + (k - sourceExtent[4]) * sliceLength + (j - sourceExtent[2]) * rowLength - sourceExtent[0];
      unsigned short* labelRow = labelVoxels + (static_cast<vtkIdType>(k) * dims[1] + j) * dims[0];
      for (int i = std::max(sourceExtent[0], 0); i <= std::min(sourceExtent[1], dims[0] - 1); ++i)
      {
        // value < 0: any voxel above zero (a mask).
        if (value < 0 ? row[i] > T(0) : static_cast<double>(row[i]) == value)
        {
          labelRow[i] = label;
        }
      }
    }
  }
}

// Marks with label the voxels of source that hold value (or, for a negative
// value, any positive value), source on the grid of labels (extent 0-based).
void CopyVoxelsOfValue(vtkImageData* source, int value, unsigned short label, vtkImageData* labels)
{
  int extent[6];
  source->GetExtent(extent);
  if (extent[1] < extent[0] || extent[3] < extent[2] || extent[5] < extent[4])
  {
    return;
  }
  switch (source->GetScalarType())
  {
    vtkTemplateMacro(CopyVoxelsOfValueTyped(static_cast<const VTK_TT*>(source->GetScalarPointer()), extent, value, label, labels));
  }
}
}

vtkStandardNewMacro(vtkSlicerVolumeCuttingSegmentImages);

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingSegmentImages::vtkSlicerVolumeCuttingSegmentImages() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingSegmentImages::~vtkSlicerVolumeCuttingSegmentImages() = default;

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSegmentImages::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSegmentImages::GetAnatomyGeometry(vtkMRMLScalarVolumeNode* anatomy, vtkOrientedImageData* geometry)
{
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  geometry->SetImageToWorldMatrix(ijkToRas);
  geometry->SetExtent(anatomy->GetImageData()->GetExtent());
}

//----------------------------------------------------------------------------
std::string vtkSlicerVolumeCuttingSegmentImages::DescribeLabelSource(
  vtkMRMLScalarVolumeNode* anatomy, vtkMRMLSegmentationNode* segmentation, const std::vector<std::string>& segmentIds)
{
  std::ostringstream source;
  for (const std::string& id : segmentIds)
  {
    source << id << ";";
  }
  if (!anatomy || !anatomy->GetImageData() || !segmentation || !segmentation->GetSegmentation())
  {
    return source.str();
  }
  for (const std::string& id : segmentIds)
  {
    vtkSegment* segment = segmentation->GetSegmentation()->GetSegment(id);
    vtkDataObject* labels = segment ? segment->GetRepresentation(vtkSegmentationConverter::GetBinaryLabelmapRepresentationName()) : nullptr;
    source << (labels ? labels->GetMTime() : 0) << ",";
  }
  source << anatomy->GetImageData()->GetMTime() << ";";
  vtkNew<vtkMatrix4x4> grid;
  anatomy->GetIJKToRASMatrix(grid);
  for (int element = 0; element < 16; ++element)
  {
    source << grid->GetElement(element / 4, element % 4) << ",";
  }
  return source.str();
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkSlicerVolumeCuttingSegmentImages::CreateLabelMap(
  vtkMRMLScalarVolumeNode* anatomy, vtkMRMLSegmentationNode* segmentationNode, const std::vector<std::string>& segmentIds, vtkImageData* labels)
{
  std::vector<std::string> missing;
  if (!labels || !anatomy || !anatomy->GetImageData())
  {
    return segmentIds;
  }
  vtkNew<vtkOrientedImageData> anatomyGeometry;
  GetAnatomyGeometry(anatomy, anatomyGeometry);
  labels->Initialize();
  labels->SetExtent(anatomy->GetImageData()->GetExtent());
  labels->AllocateScalars(VTK_UNSIGNED_SHORT, 1);
  unsigned short* labelVoxels = static_cast<unsigned short*>(labels->GetScalarPointer());
  std::fill(labelVoxels, labelVoxels + labels->GetNumberOfPoints(), static_cast<unsigned short>(0));
  for (size_t index = 0; index < segmentIds.size(); ++index)
  {
    vtkSegment* segment = segmentationNode && index < 65535 ? segmentationNode->GetSegmentation()->GetSegment(segmentIds[index]) : nullptr;
    if (!segment)
    {
      missing.push_back(segmentIds[index]);
      continue;
    }
    const unsigned short label = static_cast<unsigned short>(index + 1);
    // A segment's voxels are read from its layer in place when that layer lies
    // on the anatomy's grid, as a labelmap loaded with its scan does: extracting
    // and padding a mask of the whole grid took seconds per segment on a
    // 24-million-voxel scan, and the user waited for it at each role change.
    vtkOrientedImageData* layer = vtkOrientedImageData::SafeDownCast(
      segment->GetRepresentation(vtkSegmentationConverter::GetBinaryLabelmapRepresentationName()));
    if (layer && layer->GetPointData()->GetScalars() && IsOnGrid(layer, anatomyGeometry))
    {
      CopyVoxelsOfValue(layer, segment->GetLabelValue(), label, labels);
      continue;
    }
    vtkNew<vtkOrientedImageData> segmentMask;
    vtkNew<vtkOrientedImageData> mask;
    if (!segmentationNode->GetBinaryLabelmapRepresentation(segmentIds[index], segmentMask) ||
      !vtkOrientedImageDataResample::ResampleOrientedImageToReferenceOrientedImage(segmentMask, anatomyGeometry, mask) ||
      !mask->GetPointData()->GetScalars())
    {
      missing.push_back(segmentIds[index]);
      continue;
    }
    CopyVoxelsOfValue(mask, -1, label, labels);
  }
  return missing;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSegmentImages::CreateFraction(
  vtkMRMLScalarVolumeNode* anatomy, vtkMRMLSegmentationNode* segmentationNode, const std::string& segmentId, vtkImageData* fraction)
{
  const std::string name = vtkSegmentationConverter::GetSegmentationFractionalLabelmapRepresentationName();
  vtkSegment* segment = segmentationNode ? segmentationNode->GetSegmentation()->GetSegment(segmentId) : nullptr;
  vtkOrientedImageData* source = segment ? vtkOrientedImageData::SafeDownCast(segment->GetRepresentation(name)) : nullptr;
  if (!fraction || !anatomy || !anatomy->GetImageData() || !source || !source->GetPointData()->GetScalars())
  {
    return false;
  }
  vtkNew<vtkOrientedImageData> anatomyGeometry;
  GetAnatomyGeometry(anatomy, anatomyGeometry);
  vtkNew<vtkOrientedImageData> resampled;
  // Linear: the fractions of a segment resampled stay fractions.
  if (!vtkOrientedImageDataResample::ResampleOrientedImageToReferenceOrientedImage(source, anatomyGeometry, resampled, true))
  {
    return false;
  }
  // Slicer stores fractions as [minimum, maximum] of the representation's
  // scalar range (-108..108 for its char labelmaps); padding is outside.
  double range[2] = { -108.0, 108.0 };
  vtkDoubleArray* scalarRange = vtkDoubleArray::SafeDownCast(
    source->GetFieldData()->GetAbstractArray(vtkSegmentationConverter::GetScalarRangeFieldName()));
  if (scalarRange && scalarRange->GetNumberOfValues() == 2)
  {
    range[0] = scalarRange->GetValue(0);
    range[1] = scalarRange->GetValue(1);
  }
  fraction->Initialize();
  fraction->SetExtent(anatomy->GetImageData()->GetExtent());
  fraction->AllocateScalars(VTK_FLOAT, 1);
  fraction->GetPointData()->GetScalars()->FillComponent(0, 0.0);
  float* values = static_cast<float*>(fraction->GetScalarPointer());
  const int* dims = fraction->GetDimensions();
  int extent[6];
  resampled->GetExtent(extent);
  for (int k = std::max(extent[4], 0); k <= std::min(extent[5], dims[2] - 1); ++k)
  {
    for (int j = std::max(extent[2], 0); j <= std::min(extent[3], dims[1] - 1); ++j)
    {
      for (int i = std::max(extent[0], 0); i <= std::min(extent[1], dims[0] - 1); ++i)
      {
        const double value = (resampled->GetScalarComponentAsDouble(i, j, k, 0) - range[0]) / (range[1] - range[0]);
        values[(static_cast<vtkIdType>(k) * dims[1] + j) * dims[0] + i] = static_cast<float>(std::min(1.0, std::max(0.0, value)));
      }
    }
  }
  return true;
}
