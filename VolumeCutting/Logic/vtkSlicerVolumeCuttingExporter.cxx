/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingExporter.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutRemovedVoxels.h"

// MRML includes
#include <vtkMRMLModelDisplayNode.h>
#include <vtkMRMLModelNode.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkOrientedImageData.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPolyData.h>

vtkStandardNewMacro(vtkSlicerVolumeCuttingExporter);

namespace
{
/// The user's name for an exported node, or the source's name and a suffix.
std::string ExportName(const char* name, vtkMRMLNode* source, const char* suffix)
{
  if (name)
  {
    return name;
  }
  return std::string(source && source->GetName() ? source->GetName() : "Cut") + " " + suffix;
}
} // namespace

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingExporter::vtkSlicerVolumeCuttingExporter() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingExporter::~vtkSlicerVolumeCuttingExporter() = default;

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingExporter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}

//----------------------------------------------------------------------------
vtkMRMLSegmentationNode* vtkSlicerVolumeCuttingExporter::AddRemovedRegionSegmentation(
  vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkImageData* fraction, const char* name)
{
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  vtkNew<vtkOrientedImageData> mask;
  mask->SetExtent(fraction->GetExtent());
  mask->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  mask->SetImageToWorldMatrix(ijkToRas);
  const float* fractions = static_cast<const float*>(fraction->GetScalarPointer());
  unsigned char* voxels = static_cast<unsigned char*>(mask->GetScalarPointer());
  for (vtkIdType n = 0; n < fraction->GetNumberOfPoints(); ++n)
  {
    voxels[n] = fractions[n] >= 0.5f ? 1 : 0;
  }
  const std::string nodeName = ExportName(name, cutNode, "removed");
  vtkMRMLSegmentationNode* segmentationNode = vtkMRMLSegmentationNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLSegmentationNode", nodeName));
  segmentationNode->CreateDefaultDisplayNodes();
  segmentationNode->SetReferenceImageGeometryParameterFromVolumeNode(anatomy);
  vtkNew<vtkSegment> segment;
  segment->SetName("Removed");
  segment->SetColor(0.85, 0.15, 0.1);
  segment->AddRepresentation(vtkSegmentationConverter::GetBinaryLabelmapRepresentationName(), mask);
  segmentationNode->GetSegmentation()->AddSegment(segment, "Removed");
  return segmentationNode;
}

//----------------------------------------------------------------------------
vtkMRMLModelNode* vtkSlicerVolumeCuttingExporter::AddRemovedSurfaceModel(
  vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field, const char* name)
{
  vtkNew<vtkPolyData> surface;
  field->ExtractRemovedSurface(surface);
  const std::string nodeName = ExportName(name, cutNode, "removed surface");
  vtkMRMLModelNode* model = vtkMRMLModelNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLModelNode", nodeName));
  model->SetAndObservePolyData(surface);
  model->CreateDefaultDisplayNodes();
  if (model->GetDisplayNode())
  {
    model->GetDisplayNode()->SetColor(0.85, 0.15, 0.1);
  }
  return model;
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingExporter::AddRemovedFractionVolume(
  vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkImageData* fraction, const char* name)
{
  // A copy: the node owns its voxels, the logic keeps its fraction for the next export.
  vtkNew<vtkImageData> copy;
  copy->DeepCopy(fraction);
  return AddVolumeOnAnatomyGrid(scene, cutNode->GetAnatomyVolumeNode(), copy, ExportName(name, cutNode, "removed fraction"));
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingExporter::AddDrilledVolume(
  vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutRemovedVoxels* voxels, double fillValue, const char* name)
{
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  vtkNew<vtkImageData> drilled;
  drilled->DeepCopy(anatomy->GetImageData());
  voxels->BlendTowards(drilled, fillValue);
  return AddVolumeOnAnatomyGrid(scene, anatomy, drilled, ExportName(name, anatomy, "drilled"));
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingExporter::AddVolumeOnAnatomyGrid(
  vtkMRMLScene* scene, vtkMRMLScalarVolumeNode* anatomy, vtkImageData* image, const std::string& name)
{
  vtkMRMLScalarVolumeNode* volume = vtkMRMLScalarVolumeNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLScalarVolumeNode", name));
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  volume->SetIJKToRASMatrix(ijkToRas);
  volume->SetAndObserveImageData(image);
  volume->CreateDefaultDisplayNodes();
  return volume;
}
