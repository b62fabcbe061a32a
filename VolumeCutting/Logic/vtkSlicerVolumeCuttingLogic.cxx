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
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutMaterialRemoval.h"

// MRML includes
#include <vtkMRMLMessageCollection.h>
#include <vtkMRMLModelDisplayNode.h>
#include <vtkMRMLModelNode.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationDisplayNode.h>
#include <vtkMRMLSegmentationNode.h>

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
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkIntArray.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>

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
  const double trabecularColor[3] = { 0.85, 0.70, 0.55 };
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
  this->ProtectionSources.clear();
  this->MaterialRemovals.clear();
  this->RemovedFractions.clear();
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::OnMRMLSceneNodeRemoved(vtkMRMLNode* node)
{
  if (node && node->GetID())
  {
    this->ProtectionSources.erase(node->GetID());
    this->MaterialRemovals.erase(node->GetID());
    this->RemovedFractions.erase(node->GetID());
  }
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::OnMRMLSceneEndClose()
{
  this->ProtectionSources.clear();
  this->MaterialRemovals.clear();
  this->RemovedFractions.clear();
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
  bool matches = field != nullptr && field->GetSubVoxelFactor() == cutNode->GetSubVoxelFactor();
  if (matches)
  {
    vtkNew<vtkMatrix4x4> fieldToRas;
    field->GetSubVoxelIJKToRAS(fieldToRas);
    const int factor = field->GetSubVoxelFactor();
    for (int axis = 0; axis < 3 && matches; ++axis)
    {
      matches = field->GetDimensions()[axis] == anatomyDimensions[axis] * factor;
      for (int row = 0; row < 3 && matches; ++row)
      {
        matches = std::abs(fieldToRas->GetElement(row, axis) * factor - ijkToRas->GetElement(row, axis)) < 1e-9;
      }
    }
    // Sub-voxel 0 sits (0.5 / f - 0.5) anatomy voxels from anatomy voxel 0.
    for (int row = 0; row < 3 && matches; ++row)
    {
      double expected = ijkToRas->GetElement(row, 3);
      for (int axis = 0; axis < 3; ++axis)
      {
        expected += ijkToRas->GetElement(row, axis) * (0.5 / factor - 0.5);
      }
      matches = std::abs(fieldToRas->GetElement(row, 3) - expected) < 1e-9;
    }
  }
  if (!matches)
  {
    vtkNew<vtkVolumeCutField> newField;
    if (!newField->Initialize(anatomyDimensions, ijkToRas, cutNode->GetSubVoxelFactor()))
    {
      return nullptr;
    }
    if (field)
    {
      vtkWarningMacro("GetCutField: the anatomy grid or sub-voxel factor of '" << (cutNode->GetName() ? cutNode->GetName() : "")
                                                                                << "' changed; its cut starts anew");
    }
    cutNode->SetCutField(newField);
    this->ProtectionSources.erase(cutNode->GetID());
    this->UpdateProtection(cutNode, newField);
    return newField;
  }
  this->UpdateProtection(cutNode, field);
  return field;
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkSlicerVolumeCuttingLogic::GetShieldedSegmentIDs(vtkMRMLVolumeCutNode* cutNode)
{
  // Tool sensibility: a tool affects only cuttable segments. The others are
  // shielded: first the ones without a role, then the protected ones, so that
  // where segments overlap a protected one names the voxel.
  std::vector<std::string> shielded;
  vtkMRMLSegmentationNode* segmentationNode = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  if (!segmentationNode)
  {
    return shielded;
  }
  std::vector<std::string> segmentIds;
  segmentationNode->GetSegmentation()->GetSegmentIDs(segmentIds);
  for (const std::string& id : segmentIds)
  {
    if (!cutNode->IsSegmentCuttable(id) && !cutNode->IsSegmentProtected(id))
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
void vtkSlicerVolumeCuttingLogic::UpdateProtection(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field)
{
  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  const std::vector<std::string> protectedIds = GetShieldedSegmentIDs(cutNode);
  std::ostringstream source;
  if (segmentationNode)
  {
    source << segmentationNode->GetID() << "@" << segmentationNode->GetSegmentation()->GetMTime();
  }
  for (const std::string& id : protectedIds)
  {
    source << "|" << id;
  }
  source << "#" << protectedIds.size();
  std::string& last = this->ProtectionSources[cutNode->GetID()];
  if (last == source.str())
  {
    return;
  }
  last = source.str();
  if (!segmentationNode || protectedIds.empty())
  {
    field->SetProtectedLabels(nullptr);
    return;
  }
  vtkNew<vtkImageData> labels;
  for (const std::string& id : CreateSegmentLabelMap(cutNode, protectedIds, labels))
  {
    vtkWarningMacro("UpdateProtection: segment '" << id << "' has no labelmap on the anatomy grid; tools are not kept out of it");
  }
  field->SetProtectedLabels(labels);
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
  const std::vector<std::string> protectedIds = GetShieldedSegmentIDs(cutNode);
  const int label = field ? field->GetContactLabel() : 0;
  return label > 0 && label <= static_cast<int>(protectedIds.size()) ? protectedIds[label - 1] : std::string();
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::BeginStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field)
  {
    return false;
  }
  field->BeginStroke();
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
bool vtkSlicerVolumeCuttingLogic::NotifyCutModified(vtkMRMLVolumeCutNode* cutNode, bool changed)
{
  // Views re-render; they find the modified bricks by their stamps.
  if (changed && cutNode)
  {
    cutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::CutModifiedEvent);
  }
  return changed;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CutSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius)
{
  vtkVolumeCutField* field = this->GetStrokeField(cutNode);
  return NotifyCutModified(cutNode, field && field->CutCapsule(p0, p1, radius));
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::RestoreSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius)
{
  vtkVolumeCutField* field = this->GetStrokeField(cutNode);
  return NotifyCutModified(cutNode, field && field->RestoreCapsule(p0, p1, radius));
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CutToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  vtkVolumeCutField* field = this->GetStrokeField(cutNode);
  return NotifyCutModified(cutNode, field && field->CutToolSweep(tool, pose0, pose1));
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::RestoreToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1)
{
  vtkVolumeCutField* field = this->GetStrokeField(cutNode);
  return NotifyCutModified(cutNode, field && field->RestoreToolSweep(tool, pose0, pose1));
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::EndStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field)
  {
    return false;
  }
  field->EndStroke();
  return true;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::UndoStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  return NotifyCutModified(cutNode, field && field->Undo());
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::RedoStroke(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  return NotifyCutModified(cutNode, field && field->Redo());
}

//----------------------------------------------------------------------------
double vtkSlicerVolumeCuttingLogic::GetRemovedVolume(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  return field ? field->ComputeRemovedVolume() : 0.0;
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
  vtkImageData* fraction = this->GetRemovedFraction(cutNode);
  if (!fraction)
  {
    return -1.0;
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  vtkNew<vtkOrientedImageData> anatomyGeometry;
  GetVolumeGeometry(anatomy, anatomyGeometry);
  vtkNew<vtkOrientedImageData> segmentMask;
  if (!segmentationNode->GetBinaryLabelmapRepresentation(segmentId, segmentMask))
  {
    vtkErrorMacro("GetRemovedVolumeInSegment: segment '" << segmentId << "' has no binary labelmap");
    return -1.0;
  }
  vtkNew<vtkOrientedImageData> mask;
  if (!vtkOrientedImageDataResample::ResampleOrientedImageToReferenceOrientedImage(segmentMask, anatomyGeometry, mask))
  {
    vtkErrorMacro("GetRemovedVolumeInSegment: segment '" << segmentId << "' could not be resampled to the anatomy's grid");
    return -1.0;
  }
  int extent[6];
  mask->GetExtent(extent);
  const int* dims = fraction->GetDimensions();
  const float* fractions = static_cast<const float*>(fraction->GetScalarPointer());
  double removed = 0.0;
  for (int k = std::max(extent[4], 0); k <= std::min(extent[5], dims[2] - 1); ++k)
  {
    for (int j = std::max(extent[2], 0); j <= std::min(extent[3], dims[1] - 1); ++j)
    {
      for (int i = std::max(extent[0], 0); i <= std::min(extent[1], dims[0] - 1); ++i)
      {
        if (mask->GetScalarComponentAsDouble(i, j, k, 0) > 0.0)
        {
          removed += fractions[(static_cast<vtkIdType>(k) * dims[1] + j) * dims[0] + i];
        }
      }
    }
  }
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  return removed * std::abs(ijkToRas->Determinant());
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
  auto& cached = this->RemovedFractions[cutNode->GetID()];
  if (!cached.second || cached.first != field->GetMTime())
  {
    cached.second = vtkSmartPointer<vtkImageData>::New();
    field->ExportRemovedFraction(cached.second);
    cached.first = field->GetMTime();
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
