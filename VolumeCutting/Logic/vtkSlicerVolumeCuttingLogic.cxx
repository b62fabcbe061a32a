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
#include "vtkSlicerVolumeCuttingSegmentLayers.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutMaterialRemoval.h"
#include "vtkVolumeCutMeshTool.h"
#include "vtkVolumeCutRemovedVoxels.h"

// MRML includes
#include <vtkMRMLMessageCollection.h>
#include <vtkMRMLModelDisplayNode.h>
#include <vtkMRMLLinearTransformNode.h>
#include <vtkMRMLModelNode.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationDisplayNode.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkMRMLTableNode.h>

// SegmentationCore includes
#include <vtkBinaryLabelmapToClosedSurfaceConversionRule.h>
#include <vtkClosedSurfaceToBinaryLabelmapConversionRule.h>
#include <vtkClosedSurfaceToFractionalLabelmapConversionRule.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkSegmentationConverter.h>
#include <vtkFractionalLabelmapToClosedSurfaceConversionRule.h>
#include <vtkOrientedImageData.h>
#include <vtkOrientedImageDataResample.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>
#include <vtkSegmentationConverterFactory.h>

// VTK includes
#include <vtkCommand.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkStringArray.h>
#include <vtkDoubleArray.h>
#include <vtkTable.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkIntArray.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>

// STD includes
#include <cmath>
#include <algorithm>
#include <chrono>
#include <cstring>
#include <ctime>
#include <iomanip>
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

/// The anatomy's voxel grid as an oriented image (geometry only).
void GetVolumeGeometry(vtkMRMLScalarVolumeNode* volume, vtkOrientedImageData* geometry)
{
  vtkNew<vtkMatrix4x4> ijkToRas;
  volume->GetIJKToRASMatrix(ijkToRas);
  geometry->SetImageToWorldMatrix(ijkToRas);
  geometry->SetExtent(volume->GetImageData()->GetExtent());
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

//----------------------------------------------------------------------------
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
vtkSlicerVolumeCuttingLogic::vtkSlicerVolumeCuttingLogic()
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
    GetVolumeGeometry(anatomy, anatomyGeometry);
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
  this->CuttingTools.erase(nodeId);
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
  this->CuttingTools.clear();
  this->StrokePoses.clear();
}

//----------------------------------------------------------------------------
std::string vtkSlicerVolumeCuttingLogic::DescribeGridChange(vtkVolumeCutField* field, const int anatomyDimensions[3], vtkMatrix4x4* anatomyIJKToRAS, int factor)
{
  std::ostringstream change;
  const int fieldFactor = field->GetSubVoxelFactor();
  if (fieldFactor < 1)
  {
    return "the cut field is empty";
  }
  if (fieldFactor != factor)
  {
    change << "sub-voxel factor " << fieldFactor << " -> " << factor << "; ";
  }
  const int* fieldDimensions = field->GetDimensions();
  if (fieldDimensions[0] != anatomyDimensions[0] * fieldFactor || fieldDimensions[1] != anatomyDimensions[1] * fieldFactor ||
    fieldDimensions[2] != anatomyDimensions[2] * fieldFactor)
  {
    change << "dimensions " << fieldDimensions[0] / fieldFactor << "x" << fieldDimensions[1] / fieldFactor << "x" << fieldDimensions[2] / fieldFactor
           << " -> " << anatomyDimensions[0] << "x" << anatomyDimensions[1] << "x" << anatomyDimensions[2] << "; ";
  }
  // The field's anatomy grid, rebuilt from its sub-voxel grid.
  vtkNew<vtkMatrix4x4> subToRas;
  field->GetSubVoxelIJKToRAS(subToRas);
  double spacing = std::numeric_limits<double>::max();
  bool axesDiffer = false;
  for (int axis = 0; axis < 3; ++axis)
  {
    double length2 = 0.0;
    double difference2 = 0.0;
    for (int row = 0; row < 3; ++row)
    {
      const double a = anatomyIJKToRAS->GetElement(row, axis);
      const double d = subToRas->GetElement(row, axis) * fieldFactor - a;
      length2 += a * a;
      difference2 += d * d;
    }
    spacing = std::min(spacing, std::sqrt(length2));
    axesDiffer |= !(difference2 <= 1e-6 * length2);
  }
  if (axesDiffer)
  {
    change << "voxel spacing or axes; ";
  }
  double shift2 = 0.0;
  for (int row = 0; row < 3; ++row)
  {
    // Sub-voxel 0 sits (0.5 / f - 0.5) anatomy voxels from anatomy voxel 0.
    double expected = anatomyIJKToRAS->GetElement(row, 3);
    for (int axis = 0; axis < 3; ++axis)
    {
      expected += anatomyIJKToRAS->GetElement(row, axis) * (0.5 / fieldFactor - 0.5);
    }
    const double d = subToRas->GetElement(row, 3) - expected;
    shift2 += d * d;
  }
  if (!(std::sqrt(shift2) <= 1e-3 * spacing))
  {
    change << "origin moved by " << std::sqrt(shift2) << " mm; ";
  }
  std::string text = change.str();
  return text.empty() ? text : text.substr(0, text.size() - 2);
}

//----------------------------------------------------------------------------
vtkVolumeCutField* vtkSlicerVolumeCuttingLogic::GetCutField(vtkMRMLVolumeCutNode* cutNode)
{
  if (!cutNode || !cutNode->GetID())
  {
    vtkErrorMacro("GetCutField: no volume-cut node in a scene");
    return nullptr;
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  vtkImageData* image = anatomy ? anatomy->GetImageData() : nullptr;
  if (!image || image->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro("GetCutField: the volume-cut node '" << (cutNode->GetName() ? cutNode->GetName() : "") << "' has no anatomy volume with voxels");
    return nullptr;
  }
  int anatomyDimensions[3];
  image->GetDimensions(anatomyDimensions);
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);

  vtkVolumeCutField* field = cutNode->GetCutField();
  const bool hasCut = field && field->GetSubVoxelFactor() > 0;
  const std::string change = hasCut ? DescribeGridChange(field, anatomyDimensions, ijkToRas, cutNode->GetSubVoxelFactor()) : std::string("new");
  if (hasCut && change.empty())
  {
    this->UpdateProtection(cutNode, field);
    return field;
  }
  vtkNew<vtkVolumeCutField> newField;
  if (!newField->Initialize(anatomyDimensions, ijkToRas, cutNode->GetSubVoxelFactor()))
  {
    return nullptr;
  }
  const std::string nodeName = cutNode->GetName() ? cutNode->GetName() : "";
  if (hasCut && field->GetNumberOfAllocatedBricks() > 0)
  {
    // Nothing the user made is dropped: the cut moves onto the new grid,
    // or the change is refused if the new grid cannot hold all of it.
    newField->ResampleFrom(field);
    this->UpdateProtection(cutNode, newField, true);
    const double before = field->ComputeRemovedVolume();
    const double after = newField->ComputeRemovedVolume();
    if (std::abs(after - before) > 0.01 * before + 1e-6)
    {
      this->ProtectionSources.erase(cutNode->GetID());
      vtkErrorMacro("GetCutField: the anatomy grid of '" << nodeName << "' changed (" << change << "), and the cut of " << before
                                                         << " mm^3 would become " << after
                                                         << " mm^3 on the new grid; the change is refused and the cut is kept. Put back the anatomy"
                                                            " volume it was made on, or clear the cut to start anew.");
      return nullptr;
    }
    if (!newField->IsSameLattice(field))
    {
      vtkWarningMacro("GetCutField: the anatomy grid of '" << nodeName << "' changed (" << change << "); the cut (" << before
                                                           << " mm^3) was resampled onto the new grid (" << after << " mm^3) and its undo history cleared");
    }
    else if (field->GetNumberOfUndoSteps() > 0)
    {
      // The same voxels indexed another way (a reader reoriented the scan):
      // the cut is copied exactly; only its history cannot follow.
      vtkWarningMacro("GetCutField: the anatomy of '" << nodeName << "' was reindexed (" << change
                                                      << "); the cut was kept exactly but its undo history was cleared");
    }
  }
  cutNode->SetCutField(newField);
  this->ProtectionSources.erase(cutNode->GetID());
  this->UpdateProtection(cutNode, newField);
  return newField;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::ClearCut(vtkMRMLVolumeCutNode* cutNode)
{
  if (cutNode)
  {
    cutNode->SetCutField(nullptr);
    if (cutNode->GetID())
    {
      this->ForgetNode(cutNode->GetID());
    }
    NotifyCutModified(cutNode, true);
  }
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkSlicerVolumeCuttingLogic::GetShieldedSegmentIDs(vtkMRMLVolumeCutNode* cutNode)
{
  // Tool sensibility: a tool affects only what it may cut (the active
  // tool's own list, or the cuttable roles).
  std::vector<std::string> shielded;
  vtkMRMLSegmentationNode* segmentationNode = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  if (!segmentationNode)
  {
    return shielded;
  }
  vtkMRMLVolumeCutToolNode* tool = GetActiveTool(cutNode);
  std::vector<std::string> segmentIds;
  segmentationNode->GetSegmentation()->GetSegmentIDs(segmentIds);
  for (const std::string& id : segmentIds)
  {
    const bool mayCut = tool ? tool->MayCutSegment(cutNode, id) : cutNode->IsSegmentCuttable(id);
    if (!mayCut && !cutNode->IsSegmentProtected(id))
    {
      shielded.push_back(id);
    }
  }
  for (const std::string& id : cutNode->GetProtectedSegmentIDs())
  {
    shielded.push_back(id);
  }
  return shielded;
}

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingSegmentLayers* vtkSlicerVolumeCuttingLogic::GetSegmentLayers(vtkMRMLVolumeCutNode* cutNode)
{
  vtkMRMLSegmentationNode* segmentationNode = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  vtkMRMLScalarVolumeNode* anatomy = cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr;
  if (!segmentationNode || !anatomy || !anatomy->GetImageData() || !cutNode->GetID())
  {
    return nullptr;
  }
  auto& layers = this->SegmentLayers[cutNode->GetID()];
  if (!layers)
  {
    layers = vtkSmartPointer<vtkSlicerVolumeCuttingSegmentLayers>::New();
  }
  int dimensions[3];
  anatomy->GetImageData()->GetDimensions(dimensions);
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  return layers->Update(segmentationNode->GetSegmentation(), dimensions, ijkToRas) ? layers.GetPointer() : nullptr;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::UpdateProtection(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field, bool force)
{
  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  const std::vector<std::string> shieldedIds = GetShieldedSegmentIDs(cutNode);
  vtkSlicerVolumeCuttingSegmentLayers* layers = this->GetSegmentLayers(cutNode);
  std::ostringstream source;
  source << field;
  if (segmentationNode)
  {
    source << "|" << segmentationNode->GetID() << "@" << segmentationNode->GetSegmentation()->GetMTime();
  }
  for (const std::string& id : shieldedIds)
  {
    source << "|" << id;
  }
  source << "#" << shieldedIds.size();
  std::string& last = this->ProtectionSources[cutNode->GetID()];
  if (!force && last == source.str())
  {
    return;
  }
  last = source.str();
  // Only a table of which layer values are shielded: no volume-sized work.
  vtkVolumeCutProtection* protection = field->GetProtection();
  protection->RemoveAllLabelImages();
  this->ShieldedSegments[cutNode->GetID()] = shieldedIds;
  if (!layers || shieldedIds.empty())
  {
    return;
  }
  for (int index = 0; index < layers->GetNumberOfLayers(); ++index)
  {
    protection->AddLabelImage(layers->GetLayer(index));
  }
  if (shieldedIds.size() > 255)
  {
    vtkWarningMacro("UpdateProtection: " << shieldedIds.size() << " segments are kept out of cutting; contacts with those after the 255th are reported as the 255th");
  }
  std::vector<std::string> missing;
  for (size_t index = 0; index < shieldedIds.size(); ++index)
  {
    int value = 0;
    const int layer = layers->GetSegmentLayer(shieldedIds[index], value);
    if (layer < 0 || value < 1 || !protection->SetShieldLabel(layer, value, static_cast<int>(std::min<size_t>(index + 1, 255))))
    {
      missing.push_back(shieldedIds[index]);
    }
  }
  for (const std::string& id : missing)
  {
    vtkWarningMacro("UpdateProtection: segment '" << id << "' has no labelmap on the anatomy grid; tools are not kept out of it");
  }
  if (!layers->GetResampledSegmentIDs().empty())
  {
    vtkWarningMacro("UpdateProtection: " << layers->GetResampledSegmentIDs().size()
                                         << " segment(s) are not on the anatomy's voxel grid and were resampled onto it; their protection is only as exact as that");
  }
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkSlicerVolumeCuttingLogic::CreateSegmentLabelMap(
  vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds, vtkImageData* labels)
{
  std::vector<std::string> missing;
  vtkMRMLScalarVolumeNode* anatomy = cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr;
  vtkMRMLSegmentationNode* segmentationNode = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  if (!labels || !anatomy || !anatomy->GetImageData())
  {
    return segmentIds;
  }
  vtkNew<vtkOrientedImageData> anatomyGeometry;
  GetVolumeGeometry(anatomy, anatomyGeometry);
  labels->Initialize();
  labels->SetExtent(anatomy->GetImageData()->GetExtent());
  labels->AllocateScalars(VTK_UNSIGNED_SHORT, 1);
  labels->GetPointData()->GetScalars()->FillComponent(0, 0.0);
  unsigned short* labelVoxels = static_cast<unsigned short*>(labels->GetScalarPointer());
  const int* dims = labels->GetDimensions();
  for (size_t index = 0; index < segmentIds.size(); ++index)
  {
    vtkNew<vtkOrientedImageData> segmentMask;
    vtkNew<vtkOrientedImageData> mask;
    if (index >= 65535 || !segmentationNode || !segmentationNode->GetSegmentation()->GetSegment(segmentIds[index]) ||
      !segmentationNode->GetBinaryLabelmapRepresentation(segmentIds[index], segmentMask) ||
      !vtkOrientedImageDataResample::ResampleOrientedImageToReferenceOrientedImage(segmentMask, anatomyGeometry, mask))
    {
      missing.push_back(segmentIds[index]);
      continue;
    }
    int extent[6];
    mask->GetExtent(extent);
    for (int k = std::max(extent[4], 0); k <= std::min(extent[5], dims[2] - 1); ++k)
    {
      for (int j = std::max(extent[2], 0); j <= std::min(extent[3], dims[1] - 1); ++j)
      {
        for (int i = std::max(extent[0], 0); i <= std::min(extent[1], dims[0] - 1); ++i)
        {
          if (mask->GetScalarComponentAsDouble(i, j, k, 0) > 0.0)
          {
            labelVoxels[(static_cast<vtkIdType>(k) * dims[1] + j) * dims[0] + i] = static_cast<unsigned short>(index + 1);
          }
        }
      }
    }
  }
  return missing;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CreateSegmentFractionOnAnatomyGrid(
  vtkMRMLVolumeCutNode* cutNode, const std::string& segmentId, vtkImageData* fraction)
{
  vtkMRMLScalarVolumeNode* anatomy = cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr;
  vtkMRMLSegmentationNode* segmentationNode = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  const std::string name = vtkSegmentationConverter::GetSegmentationFractionalLabelmapRepresentationName();
  vtkSegment* segment = segmentationNode ? segmentationNode->GetSegmentation()->GetSegment(segmentId) : nullptr;
  vtkOrientedImageData* source = segment ? vtkOrientedImageData::SafeDownCast(segment->GetRepresentation(name)) : nullptr;
  if (!fraction || !anatomy || !anatomy->GetImageData() || !source || !source->GetPointData()->GetScalars())
  {
    return false;
  }
  vtkNew<vtkOrientedImageData> anatomyGeometry;
  GetVolumeGeometry(anatomy, anatomyGeometry);
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

//----------------------------------------------------------------------------
std::string vtkSlicerVolumeCuttingLogic::GetContactSegmentID(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  const int label = field ? field->GetContactLabel() : 0;
  const std::vector<std::string>& shieldedIds = this->ShieldedSegments[cutNode->GetID()];
  return label > 0 && label <= static_cast<int>(shieldedIds.size()) ? shieldedIds[label - 1] : std::string();
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::BeginStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field)
  {
    return false;
  }
  // Contacts are reported per stroke.
  field->ResetContact();
  this->ReportedContactDepths[cutNode->GetID()] = 0.0;
  // A stroke of the active tool starts where its first pose puts it.
  this->StrokePoses.erase(cutNode->GetID());
  field->BeginStroke();
  cutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::StrokeStartedEvent);
  return true;
}

//----------------------------------------------------------------------------
vtkVolumeCutField* vtkSlicerVolumeCuttingLogic::GetStrokeField(vtkMRMLVolumeCutNode* cutNode)
{
  // Inside a stroke the field was checked at BeginStroke (grid, factor,
  // protection): the poses of a haptic device, a thousand a second, go
  // straight to it.
  vtkVolumeCutField* field = cutNode ? cutNode->GetCutField() : nullptr;
  return field && field->IsStrokeOpen() ? field : this->GetCutField(cutNode);
}

//----------------------------------------------------------------------------
template <typename Apply>
bool vtkSlicerVolumeCuttingLogic::ApplyStroke(vtkMRMLVolumeCutNode* cutNode, Apply&& apply)
{
  vtkVolumeCutField* field = this->GetStrokeField(cutNode);
  if (!field)
  {
    return false;
  }
  // A pose outside a stroke is a stroke of its own.
  const bool ownStroke = !field->IsStrokeOpen();
  if (ownStroke && !this->BeginStroke(cutNode))
  {
    return false;
  }
  const bool accepted = apply(field);
  this->NotifyCutModified(cutNode, accepted);
  if (ownStroke)
  {
    this->EndStroke(cutNode);
  }
  return accepted;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::NotifyCutModified(vtkMRMLVolumeCutNode* cutNode, bool changed)
{
  if (!cutNode)
  {
    return changed;
  }
  // Views re-render; they find the modified bricks by their stamps.
  if (changed)
  {
    cutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::CutModifiedEvent);
  }
  vtkVolumeCutField* field = cutNode->GetCutField();
  if (field && cutNode->GetID() && field->GetMaximumContactDepth() > 0.0)
  {
    double& reported = this->ReportedContactDepths[cutNode->GetID()];
    if (field->GetMaximumContactDepth() > reported)
    {
      reported = field->GetMaximumContactDepth();
      cutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::ProtectedContactEvent);
    }
  }
  return changed;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CutSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius)
{
  return this->ApplyStroke(cutNode, [&](vtkVolumeCutField* field) { return field->CutCapsule(p0, p1, radius); });
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::RestoreSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius)
{
  return this->ApplyStroke(cutNode, [&](vtkVolumeCutField* field) { return field->RestoreCapsule(p0, p1, radius); });
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CutToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  return this->ApplyStroke(cutNode, [&](vtkVolumeCutField* field) { return field->CutToolSweep(tool, pose0, pose1); });
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::RestoreToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  return this->ApplyStroke(cutNode, [&](vtkVolumeCutField* field) { return field->RestoreToolSweep(tool, pose0, pose1); });
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CutSampledRegion(vtkMRMLVolumeCutNode* cutNode, vtkImageData* distances, vtkImageData* keep)
{
  return this->ApplyStroke(cutNode, [&](vtkVolumeCutField* field) { return field->CutSampledRegion(distances, keep); });
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::EndStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetStrokeField(cutNode);
  if (!field)
  {
    return false;
  }
  field->EndStroke();
  this->RecordContact(cutNode, field);
  this->UpdateTablesAfterChange(cutNode);
  cutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::StrokeEndedEvent);
  return true;
}

//----------------------------------------------------------------------------
vtkMRMLVolumeCutToolNode* vtkSlicerVolumeCuttingLogic::GetActiveTool(vtkMRMLVolumeCutNode* cutNode)
{
  return cutNode ? vtkMRMLVolumeCutToolNode::SafeDownCast(cutNode->GetActiveToolNode()) : nullptr;
}

//----------------------------------------------------------------------------
vtkVolumeCutTool* vtkSlicerVolumeCuttingLogic::GetCuttingTool(vtkMRMLVolumeCutToolNode* toolNode)
{
  if (!toolNode || !toolNode->GetID() || toolNode->GetShape() == vtkMRMLVolumeCutToolNode::Sphere)
  {
    return nullptr;
  }
  vtkMTimeType time = toolNode->GetMTime();
  vtkMRMLModelNode* model = toolNode->GetMeshModelNode();
  if (model && model->GetPolyData())
  {
    time = std::max(time, model->GetPolyData()->GetMTime());
  }
  auto& cached = this->CuttingTools[toolNode->GetID()];
  if (cached.second && cached.first == time)
  {
    return cached.second;
  }
  vtkSmartPointer<vtkVolumeCutTool> tool;
  switch (toolNode->GetShape())
  {
    case vtkMRMLVolumeCutToolNode::Cylinder:
    case vtkMRMLVolumeCutToolNode::DiskSaw:
    {
      auto cylinder = vtkSmartPointer<vtkVolumeCutCylinderTool>::New();
      cylinder->SetRadius(0.5 * toolNode->GetDiameter());
      // A disk saw is a cylinder as long as its blade is thick.
      cylinder->SetLength(toolNode->GetShape() == vtkMRMLVolumeCutToolNode::DiskSaw ? toolNode->GetThickness() : toolNode->GetLength());
      tool = cylinder;
      break;
    }
    case vtkMRMLVolumeCutToolNode::Blade:
    {
      auto box = vtkSmartPointer<vtkVolumeCutBoxTool>::New();
      box->SetSize(toolNode->GetWidth(), toolNode->GetThickness(), toolNode->GetLength());
      tool = box;
      break;
    }
    case vtkMRMLVolumeCutToolNode::Mesh:
    {
      if (!model || !model->GetPolyData() || model->GetPolyData()->GetNumberOfCells() == 0)
      {
        vtkErrorMacro("GetCuttingTool: the mesh tool '" << (toolNode->GetName() ? toolNode->GetName() : "") << "' has no model with a surface");
        return nullptr;
      }
      auto mesh = vtkSmartPointer<vtkVolumeCutMeshTool>::New();
      mesh->SetSurface(model->GetPolyData());
      tool = mesh;
      break;
    }
    default:
      return nullptr;
  }
  if (!tool->IsValid())
  {
    vtkErrorMacro("GetCuttingTool: the tool '" << (toolNode->GetName() ? toolNode->GetName() : "") << "' does not describe a valid tool");
    return nullptr;
  }
  cached = { time, tool };
  return tool;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::SweepActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1, bool cut)
{
  vtkMRMLVolumeCutToolNode* toolNode = GetActiveTool(cutNode);
  if (!toolNode)
  {
    vtkErrorMacro("SweepActiveTool: the volume-cut node '" << (cutNode && cutNode->GetName() ? cutNode->GetName() : "")
                                                          << "' has no active tool node; nothing was cut");
    return false;
  }
  if (!pose0 || !pose1)
  {
    vtkErrorMacro("SweepActiveTool: a tool pose is missing; nothing was cut");
    return false;
  }
  if (toolNode->GetShape() == vtkMRMLVolumeCutToolNode::Sphere)
  {
    // A sphere's sweep is a capsule whatever the rotation: the fast exact path.
    const double p0[3] = { pose0->GetElement(0, 3), pose0->GetElement(1, 3), pose0->GetElement(2, 3) };
    const double p1[3] = { pose1->GetElement(0, 3), pose1->GetElement(1, 3), pose1->GetElement(2, 3) };
    const double radius = toolNode->GetCuttingRadius();
    return cut ? this->CutSphereSweep(cutNode, p0, p1, radius) : this->RestoreSphereSweep(cutNode, p0, p1, radius);
  }
  vtkVolumeCutTool* tool = this->GetCuttingTool(toolNode);
  if (!tool)
  {
    return false;
  }
  return cut ? this->CutToolSweep(cutNode, tool, pose0, pose1) : this->RestoreToolSweep(cutNode, tool, pose0, pose1);
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CutWithActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  return this->SweepActiveTool(cutNode, pose0, pose1, true);
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::RestoreWithActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  return this->SweepActiveTool(cutNode, pose0, pose1, false);
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::MoveActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* toolToRAS, int action)
{
  vtkMRMLVolumeCutToolNode* toolNode = GetActiveTool(cutNode);
  if (!toolNode || !toolToRAS || !cutNode->GetID())
  {
    vtkErrorMacro("MoveActiveTool: a volume-cut node with an active tool node and a pose are required");
    return false;
  }
  for (int element = 0; element < 16; ++element)
  {
    if (!std::isfinite(toolToRAS->GetElement(element / 4, element % 4)))
    {
      vtkErrorMacro("MoveActiveTool: the pose of '" << (toolNode->GetName() ? toolNode->GetName() : "") << "' is not finite; the tool did not move");
      return false;
    }
  }
  // The tool's glyph follows in every view.
  vtkMRMLLinearTransformNode* transform = vtkMRMLLinearTransformNode::SafeDownCast(toolNode->GetParentTransformNode());
  if (transform)
  {
    transform->SetMatrixTransformToParent(toolToRAS);
  }
  vtkVolumeCutField* field = cutNode->GetCutField();
  bool accepted = true;
  if (action == ToolMove && !(field && field->IsStrokeOpen()) && (field = this->GetCutField(cutNode)) != nullptr)
  {
    // Hovering: the shield around the tool is built now, before it cuts there.
    const double center[3] = { toolToRAS->GetElement(0, 3), toolToRAS->GetElement(1, 3), toolToRAS->GetElement(2, 3) };
    field->PrepareProtection(center, toolNode->GetBoundingRadius() + 2.0);
  }
  if (action != ToolMove && field && field->IsStrokeOpen())
  {
    // The first pose of a stroke cuts where it is; the next ones sweep from the last.
    vtkSmartPointer<vtkMatrix4x4>& previous = this->StrokePoses[cutNode->GetID()];
    accepted = this->SweepActiveTool(cutNode, previous ? previous.GetPointer() : toolToRAS, toolToRAS, action == ToolCut);
    if (!previous)
    {
      previous = vtkSmartPointer<vtkMatrix4x4>::New();
    }
    previous->DeepCopy(toolToRAS);
  }
  return accepted;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::DrillWithActiveTool(vtkMRMLVolumeCutNode* cutNode, const double center[3], const double axis[3], double dt)
{
  vtkMRMLVolumeCutToolNode* toolNode = GetActiveTool(cutNode);
  if (!toolNode)
  {
    vtkErrorMacro("DrillWithActiveTool: the volume-cut node has no active tool node");
    return false;
  }
  // The rate follows the pedal: power scales the time the burr works.
  return this->DrillWithMaterialRemoval(cutNode, center, axis, toolNode->GetCuttingRadius(), dt * toolNode->GetPower(),
    toolNode->GetBurrType() == vtkMRMLVolumeCutToolNode::Diamond ? vtkVolumeCutMaterialRemoval::DiamondBurr : vtkVolumeCutMaterialRemoval::CuttingBurr);
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::UndoStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  const bool undone = this->NotifyCutModified(cutNode, field && field->Undo());
  this->UpdateTablesAfterChange(cutNode);
  return undone;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::RedoStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  const bool redone = this->NotifyCutModified(cutNode, field && field->Redo());
  this->UpdateTablesAfterChange(cutNode);
  return redone;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::UpdateTablesAfterChange(vtkMRMLVolumeCutNode* cutNode)
{
  // Only a table the user asked for is kept up to date: its cost follows the cut.
  if (cutNode && cutNode->GetNodeReference(GetRemovedVolumeTableReferenceRole()))
  {
    this->UpdateRemovedVolumeTable(cutNode);
  }
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::RecordContact(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field)
{
  const double depth = field->GetMaximumContactDepth();
  if (!(depth > 0.0) || !cutNode->GetID())
  {
    return;
  }
  vtkMRMLTableNode* table = this->GetContactTableNode(cutNode);
  if (!table)
  {
    return;
  }
  const std::string segmentId = this->GetContactSegmentID(cutNode);
  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  vtkSegment* segment = segmentationNode && !segmentId.empty() ? segmentationNode->GetSegmentation()->GetSegment(segmentId) : nullptr;
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
#ifdef _WIN32
  gmtime_s(&utc, &now);
#else
  gmtime_r(&now, &utc);
#endif
  std::ostringstream time;
  time << std::put_time(&utc, "%Y-%m-%dT%H:%M:%SZ");
  const double* position = field->GetContactPosition();
  const int row = table->AddEmptyRow();
  table->SetCellText(row, 0, segmentId.c_str());
  table->SetCellText(row, 1, segment && segment->GetName() ? segment->GetName() : "");
  table->SetCellText(row, 2, time.str().c_str());
  std::ostringstream value;
  for (int column = 3; column < 7; ++column)
  {
    value.str("");
    value << (column == 3 ? depth : position[column - 4]);
    table->SetCellText(row, column, value.str().c_str());
  }
}

//----------------------------------------------------------------------------
double vtkSlicerVolumeCuttingLogic::GetRemovedVolume(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  if (!voxels)
  {
    return 0.0;
  }
  vtkNew<vtkMatrix4x4> ijkToRas;
  cutNode->GetAnatomyVolumeNode()->GetIJKToRASMatrix(ijkToRas);
  return voxels->GetTotalFraction() * std::abs(ijkToRas->Determinant());
}

//----------------------------------------------------------------------------
vtkVolumeCutRemovedVoxels* vtkSlicerVolumeCuttingLogic::UpdateRemovedVoxels(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field)
  {
    return nullptr;
  }
  vtkSmartPointer<vtkVolumeCutRemovedVoxels>& voxels = this->RemovedVoxels[cutNode->GetID()];
  if (!voxels)
  {
    voxels = vtkSmartPointer<vtkVolumeCutRemovedVoxels>::New();
  }
  voxels->Update(field);
  return voxels;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::GetRemovedVoxels(vtkMRMLVolumeCutNode* cutNode, vtkIdTypeArray* voxelIds, vtkFloatArray* fractions)
{
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  if (!voxels)
  {
    return false;
  }
  voxels->GetVoxels(voxelIds, fractions);
  return true;
}

//----------------------------------------------------------------------------
std::map<std::string, double> vtkSlicerVolumeCuttingLogic::ComputeRemovedVolumePerSegment(
  vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds)
{
  std::map<std::string, double> volumes;
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  vtkSlicerVolumeCuttingSegmentLayers* layers = voxels ? this->GetSegmentLayers(cutNode) : nullptr;
  if (!layers)
  {
    return volumes;
  }
  // Which segment each (layer, value) stands for; one read per layer and voxel.
  std::vector<std::map<int, std::vector<std::string>>> byValue(static_cast<size_t>(layers->GetNumberOfLayers()));
  for (const std::string& segmentId : segmentIds)
  {
    int value = 0;
    const int layer = layers->GetSegmentLayer(segmentId, value);
    if (layer >= 0)
    {
      byValue[layer][value].push_back(segmentId);
      volumes[segmentId] = 0.0;
    }
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  const int* dims = anatomy->GetImageData()->GetDimensions();
  std::vector<double> sums;
  voxels->ForEachVoxel([&](vtkIdType id, float fraction) {
    const int i = static_cast<int>(id % dims[0]);
    const int j = static_cast<int>((id / dims[0]) % dims[1]);
    const int k = static_cast<int>(id / (static_cast<vtkIdType>(dims[0]) * dims[1]));
    for (int layer = 0; layer < layers->GetNumberOfLayers(); ++layer)
    {
      if (byValue[layer].empty())
      {
        continue;
      }
      vtkImageData* image = layers->GetLayer(layer);
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
          volumes[segmentId] += fraction;
        }
      }
    }
  });
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  const double voxelVolume = std::abs(ijkToRas->Determinant());
  for (auto& entry : volumes)
  {
    entry.second *= voxelVolume;
  }
  return volumes;
}

//----------------------------------------------------------------------------
double vtkSlicerVolumeCuttingLogic::GetRemovedVolumeInSegment(vtkMRMLVolumeCutNode* cutNode, const char* segmentId)
{
  vtkMRMLSegmentationNode* segmentationNode = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  if (!segmentationNode || !segmentId || !segmentationNode->GetSegmentation()->GetSegment(segmentId))
  {
    vtkErrorMacro("GetRemovedVolumeInSegment: no segment '" << (segmentId ? segmentId : "") << "' in the cut node's segmentation");
    return -1.0;
  }
  if (!this->GetCutField(cutNode))
  {
    return -1.0;
  }
  const std::map<std::string, double> volumes = this->ComputeRemovedVolumePerSegment(cutNode, { segmentId });
  auto found = volumes.find(segmentId);
  if (found == volumes.end())
  {
    vtkErrorMacro("GetRemovedVolumeInSegment: segment '" << segmentId << "' has no binary labelmap");
    return -1.0;
  }
  return found->second;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::GetReferencedTable(
  vtkMRMLVolumeCutNode* cutNode, const char* role, const char* nameSuffix, const std::vector<std::string>& columns)
{
  if (!cutNode || !this->GetMRMLScene())
  {
    vtkErrorMacro("GetReferencedTable: no volume-cut node in a scene");
    return nullptr;
  }
  vtkMRMLTableNode* table = vtkMRMLTableNode::SafeDownCast(cutNode->GetNodeReference(role));
  if (table)
  {
    return table;
  }
  const std::string name = this->GetMRMLScene()->GenerateUniqueName(std::string(cutNode->GetName() ? cutNode->GetName() : "Cut") + " " + nameSuffix);
  table = vtkMRMLTableNode::SafeDownCast(this->GetMRMLScene()->AddNewNodeByClass("vtkMRMLTableNode", name));
  if (!table)
  {
    return nullptr;
  }
  for (const std::string& column : columns)
  {
    vtkNew<vtkStringArray> array;
    array->SetName(column.c_str());
    table->AddColumn(array);
  }
  cutNode->SetNodeReferenceID(role, table->GetID());
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::GetRemovedVolumeTableNode(vtkMRMLVolumeCutNode* cutNode)
{
  const bool existed = cutNode && cutNode->GetNodeReference(GetRemovedVolumeTableReferenceRole());
  vtkMRMLTableNode* table =
    this->GetReferencedTable(cutNode, GetRemovedVolumeTableReferenceRole(), "removed volume", { "Segment", "Name", "Role", "Removed volume" });
  if (table && !existed)
  {
    table->SetColumnUnitLabel("Removed volume", "mm3");
    table->SetColumnDescription("Removed volume", "Volume removed inside the segment by the cut");
    this->UpdateRemovedVolumeTable(cutNode);
  }
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::GetContactTableNode(vtkMRMLVolumeCutNode* cutNode)
{
  const bool existed = cutNode && cutNode->GetNodeReference(GetContactTableReferenceRole());
  vtkMRMLTableNode* table = this->GetReferencedTable(cutNode, GetContactTableReferenceRole(), "contacts", { "Segment", "Name", "Time", "Depth", "R", "A", "S" });
  if (table && !existed)
  {
    table->SetColumnUnitLabel("Depth", "mm");
    table->SetColumnDescription("Depth", "Deepest penetration of the tool into a segment it may not cut, in one stroke");
    table->SetColumnDescription("Time", "End of the stroke (UTC)");
  }
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::UpdateRemovedVolumeTable(vtkMRMLVolumeCutNode* cutNode)
{
  vtkMRMLTableNode* table = vtkMRMLTableNode::SafeDownCast(cutNode ? cutNode->GetNodeReference(GetRemovedVolumeTableReferenceRole()) : nullptr);
  if (!table)
  {
    return this->GetRemovedVolumeTableNode(cutNode);
  }
  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  std::vector<std::string> segmentIds;
  if (segmentationNode)
  {
    segmentationNode->GetSegmentation()->GetSegmentIDs(segmentIds);
  }
  const std::map<std::string, double> volumes = this->ComputeRemovedVolumePerSegment(cutNode, segmentIds);
  const int wasModifying = table->StartModify();
  table->GetTable()->SetNumberOfRows(0);
  for (const std::string& segmentId : segmentIds)
  {
    auto found = volumes.find(segmentId);
    const double removed = found != volumes.end() ? found->second : 0.0;
    vtkSegment* segment = segmentationNode->GetSegmentation()->GetSegment(segmentId);
    const int row = table->AddEmptyRow();
    table->SetCellText(row, 0, segmentId.c_str());
    table->SetCellText(row, 1, segment && segment->GetName() ? segment->GetName() : "");
    table->SetCellText(row, 2, cutNode->IsSegmentCuttable(segmentId) ? "cuttable" : cutNode->IsSegmentProtected(segmentId) ? "protected" : "none");
    std::ostringstream text;
    text << std::fixed << std::setprecision(3) << std::max(0.0, removed);
    table->SetCellText(row, 3, text.str().c_str());
  }
  table->EndModify(wasModifying);
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLSegmentationNode* vtkSlicerVolumeCuttingLogic::ExportRemovedRegionToSegmentation(vtkMRMLVolumeCutNode* cutNode, const char* name)
{
  vtkImageData* fraction = this->GetRemovedFraction(cutNode);
  if (!fraction || !this->GetMRMLScene())
  {
    return nullptr;
  }
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
  vtkMRMLSegmentationNode* segmentationNode = vtkMRMLSegmentationNode::SafeDownCast(this->GetMRMLScene()->AddNewNodeByClass("vtkMRMLSegmentationNode", nodeName));
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
vtkMRMLModelNode* vtkSlicerVolumeCuttingLogic::ExportRemovedSurfaceToModel(vtkMRMLVolumeCutNode* cutNode, const char* name)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field || !this->GetMRMLScene())
  {
    return nullptr;
  }
  vtkNew<vtkPolyData> surface;
  field->ExtractRemovedSurface(surface);
  const std::string nodeName = ExportName(name, cutNode, "removed surface");
  vtkMRMLModelNode* model = vtkMRMLModelNode::SafeDownCast(this->GetMRMLScene()->AddNewNodeByClass("vtkMRMLModelNode", nodeName));
  model->SetAndObservePolyData(surface);
  model->CreateDefaultDisplayNodes();
  if (model->GetDisplayNode())
  {
    model->GetDisplayNode()->SetColor(0.85, 0.15, 0.1);
  }
  return model;
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingLogic::ExportDrilledVolume(vtkMRMLVolumeCutNode* cutNode, double fillValue, const char* name)
{
  vtkImageData* fraction = this->GetRemovedFraction(cutNode);
  if (!fraction || !this->GetMRMLScene())
  {
    return nullptr;
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  vtkNew<vtkImageData> drilled;
  drilled->DeepCopy(anatomy->GetImageData());
  vtkDataArray* voxels = drilled->GetPointData()->GetScalars();
  const float* fractions = static_cast<const float*>(fraction->GetScalarPointer());
  const vtkIdType voxelCount = std::min(drilled->GetNumberOfPoints(), fraction->GetNumberOfPoints());
  for (vtkIdType n = 0; n < voxelCount; ++n)
  {
    if (fractions[n] > 0.0f)
    {
      const double value = voxels->GetComponent(n, 0);
      voxels->SetComponent(n, 0, value + fractions[n] * (fillValue - value));
    }
  }
  return this->AddVolumeOnAnatomyGrid(anatomy, drilled, ExportName(name, anatomy, "drilled"));
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::DrillWithMaterialRemoval(vtkMRMLVolumeCutNode* cutNode, const double center[3], const double axis[3], double radius,
                                                           double dt, int burrType)
{
  vtkVolumeCutField* field = this->GetStrokeField(cutNode);
  vtkMRMLScalarVolumeNode* anatomy = cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr;
  if (!field || !anatomy || !anatomy->GetImageData())
  {
    vtkErrorMacro("DrillWithMaterialRemoval: the cut node needs an anatomy volume with voxels");
    return false;
  }
  vtkSmartPointer<vtkVolumeCutMaterialRemoval>& remover = this->MaterialRemovals[cutNode->GetID()];
  if (!remover)
  {
    remover = vtkSmartPointer<vtkVolumeCutMaterialRemoval>::New();
  }
  // New inputs (a new field or anatomy) restart the exposure.
  if (!remover->SetInputsIfChanged(field, anatomy->GetImageData()))
  {
    return false;
  }
  remover->SetBurrType(burrType);
  return NotifyCutModified(cutNode, remover->Drill(center, axis, radius, dt));
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::ResetMaterialRemoval(vtkMRMLVolumeCutNode* cutNode)
{
  if (cutNode && cutNode->GetID())
  {
    this->MaterialRemovals.erase(cutNode->GetID());
  }
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingLogic::ExportRemovedFractionToVolume(vtkMRMLVolumeCutNode* cutNode, const char* name)
{
  vtkImageData* fraction = this->GetRemovedFraction(cutNode);
  if (!fraction || !this->GetMRMLScene())
  {
    return nullptr;
  }
  // A copy: the node owns its voxels, the cached fraction stays the logic's.
  vtkNew<vtkImageData> copy;
  copy->DeepCopy(fraction);
  return this->AddVolumeOnAnatomyGrid(cutNode->GetAnatomyVolumeNode(), copy, ExportName(name, cutNode, "removed fraction"));
}

//----------------------------------------------------------------------------
vtkImageData* vtkSlicerVolumeCuttingLogic::GetRemovedFraction(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field)
  {
    return nullptr;
  }
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  auto& cached = this->RemovedFractions[cutNode->GetID()];
  if (!cached.second || cached.first != voxels->GetMTime())
  {
    // Dense, from the tally of removed voxels: only the cut's voxels are written.
    const int* dims = cutNode->GetAnatomyVolumeNode()->GetImageData()->GetDimensions();
    cached.second = vtkSmartPointer<vtkImageData>::New();
    cached.second->SetDimensions(dims[0], dims[1], dims[2]);
    cached.second->AllocateScalars(VTK_FLOAT, 1);
    vtkFloatArray* scalars = vtkFloatArray::SafeDownCast(cached.second->GetPointData()->GetScalars());
    scalars->SetName("RemovedFraction");
    scalars->FillValue(0.0f);
    float* values = scalars->GetPointer(0);
    voxels->ForEachVoxel([values](vtkIdType id, float fraction) { values[id] = fraction; });
    cached.first = voxels->GetMTime();
  }
  return cached.second;
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingLogic::AddVolumeOnAnatomyGrid(vtkMRMLScalarVolumeNode* anatomy, vtkImageData* image, const std::string& name)
{
  vtkMRMLScalarVolumeNode* volume = vtkMRMLScalarVolumeNode::SafeDownCast(this->GetMRMLScene()->AddNewNodeByClass("vtkMRMLScalarVolumeNode", name));
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  volume->SetIJKToRASMatrix(ijkToRas);
  volume->SetAndObserveImageData(image);
  volume->CreateDefaultDisplayNodes();
  return volume;
}
