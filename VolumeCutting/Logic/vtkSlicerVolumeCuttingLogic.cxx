/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingLogic.h"

// VolumeCutting includes
#include "vtkImageBoneSegmentation.h"
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutStorageNode.h"
#include "vtkMRMLVolumeCutToolDisplayNode.h"
#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkSlicerVolumeCuttingSegmentImages.h"
#include "vtkSlicerVolumeCuttingSegmentLayers.h"
#include "vtkSlicerVolumeCuttingNerveMonitors.h"
#include "vtkSlicerVolumeCuttingToolCache.h"
#include "vtkVolumeCutMaterialRemoval.h"
#include "vtkVolumeCutRemovedVoxels.h"

// MRML includes
#include <vtkMRMLMessageCollection.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkBinaryLabelmapToClosedSurfaceConversionRule.h>
#include <vtkClosedSurfaceToBinaryLabelmapConversionRule.h>
#include <vtkClosedSurfaceToFractionalLabelmapConversionRule.h>
#include <vtkFractionalLabelmapToClosedSurfaceConversionRule.h>
#include <vtkOrientedImageData.h>
#include <vtkOrientedImageDataResample.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>
#include <vtkSegmentationConverterFactory.h>

// VTK includes
#include <vtkCommand.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>

// STD includes
#include <cmath>
#include <cstring>
#include <sstream>

vtkStandardNewMacro(vtkSlicerVolumeCuttingLogic);

namespace
{
void Report(vtkMRMLMessageCollection* messages, unsigned long type, const std::string& text)
{
  if (messages)
  {
    messages->AddMessage(type, text);
  }
}

void AddLabelAsSegment(vtkSegmentation* segmentation, vtkImageData* labels, unsigned char label, vtkMatrix4x4* ijkToRas, const char* segmentId, const char* name,
                       const double color[3])
{
  vtkNew<vtkOrientedImageData> mask;
  mask->SetExtent(labels->GetExtent());
  mask->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  mask->SetImageToWorldMatrix(ijkToRas);
  const unsigned char* source = static_cast<const unsigned char*>(labels->GetScalarPointer());
  unsigned char* target = static_cast<unsigned char*>(mask->GetScalarPointer());
  const vtkIdType voxelCount = labels->GetNumberOfPoints();
  for (vtkIdType index = 0; index < voxelCount; ++index)
  {
    target[index] = source[index] == label ? 1 : 0;
  }
  vtkNew<vtkSegment> segment;
  segment->SetName(name);
  segment->SetColor(color[0], color[1], color[2]);
  segment->AddRepresentation(vtkSegmentationConverter::GetBinaryLabelmapRepresentationName(), mask);
  segmentation->AddSegment(segment, segmentId);
}
} // namespace

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingLogic::vtkSlicerVolumeCuttingLogic()
  : ToolCache(vtkSmartPointer<vtkSlicerVolumeCuttingToolCache>::New())
  , NerveMonitors(vtkSmartPointer<vtkSlicerVolumeCuttingNerveMonitors>::New())
{
  RegisterSegmentationConverterRules();
}

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingLogic::~vtkSlicerVolumeCuttingLogic() = default;

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::RegisterSegmentationConverterRules()
{
  vtkSegmentationConverterFactory* factory = vtkSegmentationConverterFactory::GetInstance();
  auto registerOnce = [factory](vtkSegmentationConverterRule* newRule) {
    for (const auto& rule : factory->GetConverterRules())
    {
      if (strcmp(rule->GetClassName(), newRule->GetClassName()) == 0)
      {
        return;
      }
    }
    factory->RegisterConverterRule(newRule);
  };
  registerOnce(vtkSmartPointer<vtkBinaryLabelmapToClosedSurfaceConversionRule>::New());
  registerOnce(vtkSmartPointer<vtkClosedSurfaceToBinaryLabelmapConversionRule>::New());
  registerOnce(vtkSmartPointer<vtkFractionalLabelmapToClosedSurfaceConversionRule>::New());
  registerOnce(vtkSmartPointer<vtkClosedSurfaceToFractionalLabelmapConversionRule>::New());
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::RegisterNodes()
{
  if (!this->GetMRMLScene())
  {
    vtkErrorMacro("RegisterNodes: no scene");
    return;
  }
  this->GetMRMLScene()->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutNode>::New());
  this->GetMRMLScene()->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutStorageNode>::New());
  this->GetMRMLScene()->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutToolNode>::New());
  this->GetMRMLScene()->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutToolDisplayNode>::New());
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::SetMRMLSceneInternal(vtkMRMLScene* newScene)
{
  vtkNew<vtkIntArray> events;
  events->InsertNextValue(vtkMRMLScene::NodeRemovedEvent);
  events->InsertNextValue(vtkMRMLScene::EndCloseEvent);
  this->SetAndObserveMRMLSceneEventsInternal(newScene, events);
  this->ForgetAllNodes();
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::OnMRMLSceneNodeRemoved(vtkMRMLNode* node)
{
  if (node && node->GetID())
  {
    this->ForgetNode(node->GetID());
  }
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::OnMRMLSceneEndClose()
{
  this->ForgetAllNodes();
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::ForgetNode(const std::string& nodeId)
{
  this->ProtectionSources.erase(nodeId);
  this->MaterialRemovals.erase(nodeId);
  this->RemovedFractions.erase(nodeId);
  this->RemovedVoxels.erase(nodeId);
  this->SegmentLayers.erase(nodeId);
  this->ShieldedSegments.erase(nodeId);
  this->ReportedContactDepths.erase(nodeId);
  this->ToolCache->Forget(nodeId);
  this->NerveMonitors->Forget(nodeId);
  this->BoneAheadQueries.erase(nodeId);
  this->StrokePoses.erase(nodeId);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::ForgetAllNodes()
{
  this->ProtectionSources.clear();
  this->MaterialRemovals.clear();
  this->RemovedFractions.clear();
  this->RemovedVoxels.clear();
  this->SegmentLayers.clear();
  this->ShieldedSegments.clear();
  this->ReportedContactDepths.clear();
  this->ToolCache->ForgetAll();
  this->NerveMonitors->ForgetAll();
  this->BoneAheadQueries.clear();
  this->StrokePoses.clear();
}

//----------------------------------------------------------------------------
vtkMRMLSegmentationNode* vtkSlicerVolumeCuttingLogic::CreateBoneSegmentation(vtkMRMLScalarVolumeNode* anatomyVolume,
                                                                             double corticalThreshold,
                                                                             double trabecularThreshold,
                                                                             double smoothingStandardDeviationMm)
{
  vtkMRMLScene* scene = this->GetMRMLScene();
  if (!scene || !anatomyVolume || !anatomyVolume->GetImageData() || anatomyVolume->GetImageData()->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro("CreateBoneSegmentation: a scene and an anatomy volume with voxels are required");
    return nullptr;
  }

  vtkNew<vtkImageData> ijkImage;
  ijkImage->ShallowCopy(anatomyVolume->GetImageData());
  // Smoothing is specified in millimetres: give the filter the real spacing.
  ijkImage->SetSpacing(anatomyVolume->GetSpacing());
  vtkNew<vtkImageBoneSegmentation> boneSegmentation;
  boneSegmentation->SetInputData(ijkImage);
  boneSegmentation->SetCorticalThreshold(corticalThreshold);
  boneSegmentation->SetTrabecularThreshold(trabecularThreshold);
  boneSegmentation->SetSmoothingStandardDeviation(smoothingStandardDeviationMm);
  boneSegmentation->Update();
  vtkImageData* labels = boneSegmentation->GetOutput();
  if (!labels->GetPointData()->GetScalars() || labels->GetNumberOfPoints() != anatomyVolume->GetImageData()->GetNumberOfPoints())
  {
    vtkErrorMacro("CreateBoneSegmentation: bone segmentation of '" << (anatomyVolume->GetName() ? anatomyVolume->GetName() : "") << "' failed");
    return nullptr;
  }

  std::string name = std::string(anatomyVolume->GetName() ? anatomyVolume->GetName() : "Volume") + " bone";
  vtkMRMLSegmentationNode* segmentationNode = vtkMRMLSegmentationNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLSegmentationNode", name));
  segmentationNode->CreateDefaultDisplayNodes();
  segmentationNode->SetReferenceImageGeometryParameterFromVolumeNode(anatomyVolume);

  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomyVolume->GetIJKToRASMatrix(ijkToRas);
  const double corticalColor[3] = { 0.95, 0.91, 0.79 };
  // Cancellous bone looks redder (marrow) than the cortex where a cut exposes it.
  const double trabecularColor[3] = { 0.80, 0.52, 0.40 };
  vtkSegmentation* segmentation = segmentationNode->GetSegmentation();
  AddLabelAsSegment(segmentation, labels, vtkImageBoneSegmentation::CorticalLabel, ijkToRas, GetCorticalBoneSegmentID(), "Cortical bone", corticalColor);
  AddLabelAsSegment(segmentation, labels, vtkImageBoneSegmentation::TrabecularLabel, ijkToRas, GetTrabecularBoneSegmentID(), "Trabecular bone", trabecularColor);
  return segmentationNode;
}

//----------------------------------------------------------------------------
vtkMRMLVolumeCutNode* vtkSlicerVolumeCuttingLogic::AddVolumeCutNode(vtkMRMLScalarVolumeNode* anatomyVolume, vtkMRMLSegmentationNode* segmentation)
{
  vtkMRMLScene* scene = this->GetMRMLScene();
  if (!scene)
  {
    vtkErrorMacro("AddVolumeCutNode: no scene");
    return nullptr;
  }
  std::string name = scene->GenerateUniqueName(std::string(anatomyVolume && anatomyVolume->GetName() ? anatomyVolume->GetName() : "Volume") + " cut");
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutNode", name));
  if (!cutNode)
  {
    vtkErrorMacro("AddVolumeCutNode: vtkMRMLVolumeCutNode is not registered in the scene");
    return nullptr;
  }
  if (anatomyVolume)
  {
    cutNode->SetAndObserveAnatomyVolumeNodeID(anatomyVolume->GetID());
  }
  if (segmentation)
  {
    cutNode->SetAndObserveSegmentationNodeID(segmentation->GetID());
    const std::string geometryParameter = vtkSegmentationConverter::GetReferenceImageGeometryParameterName();
    if (anatomyVolume && anatomyVolume->GetImageData() && segmentation->GetSegmentation()->GetConversionParameter(geometryParameter).empty())
    {
      segmentation->SetReferenceImageGeometryParameterFromVolumeNode(anatomyVolume);
    }
  }
  return cutNode;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CheckInputs(vtkMRMLVolumeCutNode* cutNode, vtkMRMLMessageCollection* messages)
{
  bool valid = true;
  auto error = [&](const std::string& text) {
    Report(messages, vtkCommand::ErrorEvent, text);
    vtkErrorMacro("CheckInputs: " << text);
    valid = false;
  };
  auto warning = [&](const std::string& text) {
    Report(messages, vtkCommand::WarningEvent, text);
    vtkWarningMacro("CheckInputs: " << text);
  };

  if (!cutNode)
  {
    error("no volume-cut node");
    return false;
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  vtkImageData* image = anatomy ? anatomy->GetImageData() : nullptr;
  if (!anatomy)
  {
    error("no anatomy volume is selected");
  }
  else if (!image || image->GetNumberOfPoints() == 0 || !image->GetPointData()->GetScalars())
  {
    error("the anatomy volume '" + std::string(anatomy->GetName() ? anatomy->GetName() : "") + "' has no voxels");
  }
  else
  {
    const double* spacing = anatomy->GetSpacing();
    for (int axis = 0; axis < 3; ++axis)
    {
      if (!std::isfinite(spacing[axis]) || spacing[axis] <= 0.0)
      {
        std::ostringstream text;
        text << "the anatomy volume's spacing along axis " << axis << " is " << spacing[axis] << "; it must be a positive number";
        error(text.str());
        break;
      }
    }
  }

  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  if (!segmentationNode)
  {
    warning("no segmentation is selected: no segment can be protected");
  }
  else if (valid && anatomy)
  {
    vtkNew<vtkOrientedImageData> anatomyGeometry;
    vtkSlicerVolumeCuttingSegmentImages::GetAnatomyGeometry(anatomy, anatomyGeometry);
    vtkSegmentation* segmentation = segmentationNode->GetSegmentation();
    const std::string geometryString = segmentation->GetConversionParameter(vtkSegmentationConverter::GetReferenceImageGeometryParameterName());
    vtkNew<vtkOrientedImageData> segmentationGeometry;
    bool hasGeometry = !geometryString.empty() && vtkSegmentationConverter::DeserializeImageGeometry(geometryString, segmentationGeometry, false);
    if (!hasGeometry)
    {
      // No reference geometry: the first segment's labelmap tells the grid.
      std::vector<std::string> segmentIds;
      segmentation->GetSegmentIDs(segmentIds);
      for (const std::string& segmentId : segmentIds)
      {
        vtkOrientedImageData* labelmap = vtkOrientedImageData::SafeDownCast(
          segmentation->GetSegment(segmentId)->GetRepresentation(vtkSegmentationConverter::GetBinaryLabelmapRepresentationName()));
        if (labelmap)
        {
          vtkNew<vtkMatrix4x4> imageToWorld;
          labelmap->GetImageToWorldMatrix(imageToWorld);
          segmentationGeometry->SetImageToWorldMatrix(imageToWorld);
          hasGeometry = true;
          break;
        }
      }
    }
    if (hasGeometry && !vtkOrientedImageDataResample::DoGeometriesMatch(anatomyGeometry, segmentationGeometry))
    {
      warning("the segmentation '" + std::string(segmentationNode->GetName() ? segmentationNode->GetName() : "")
              + "' is not on the anatomy's voxel grid (spacing, origin or axes differ): segments will be resampled, and protection is only as exact as that grid");
    }
    std::vector<std::string> roleIds = cutNode->GetCuttableSegmentIDs();
    const std::vector<std::string> protectedIds = cutNode->GetProtectedSegmentIDs();
    roleIds.insert(roleIds.end(), protectedIds.begin(), protectedIds.end());
    for (const std::string& segmentId : roleIds)
    {
      if (!segmentation->GetSegment(segmentId))
      {
        warning("segment '" + segmentId + "' has a role but is not in the segmentation");
      }
    }
  }
  return valid;
}
