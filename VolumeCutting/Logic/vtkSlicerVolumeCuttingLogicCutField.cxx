/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// The cut field of a cut node: created on the anatomy's grid, moved onto a
// new grid when the anatomy changes, and shielded from the segments the
// active tool may not cut. Part of vtkSlicerVolumeCuttingLogic.

#include "vtkSlicerVolumeCuttingLogic.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkSlicerVolumeCuttingNerveMonitors.h"
#include "vtkSlicerVolumeCuttingSegmentImages.h"
#include "vtkSlicerVolumeCuttingSegmentLayers.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutGridChange.h"

// MRML includes
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkSegmentation.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

// STD includes
#include <algorithm>
#include <cmath>
#include <sstream>

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
  const std::string change = hasCut ? vtkVolumeCutGridChange::Describe(field, anatomyDimensions, ijkToRas, cutNode->GetSubVoxelFactor()) : std::string("new");
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
    // Both volumes with the shield or both without: a field read from a
    // file has none yet, and counts the ramp of a cut surface that reaches
    // into a shielded voxel, which the shield's smoothed wall comes close to.
    const bool shieldedBefore = field->GetProtection()->HasShieldedLabels();
    if (shieldedBefore)
    {
      this->UpdateProtection(cutNode, newField, true);
    }
    const double before = field->ComputeRemovedVolume();
    const double after = newField->ComputeRemovedVolume();
    if (!shieldedBefore)
    {
      this->UpdateProtection(cutNode, newField, true);
    }
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
  // The wall a tool leaves against a structure is the surface drawn for it.
  field->GetProtection()->SetSurfaceSmoothing(cutNode->GetLabelSmoothing());
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
  if (this->NerveMonitoring)
  {
    // The monitor's fields take seconds to build (on a worker): start them
    // with the shield, not at the first pose that reads them.
    this->NerveMonitors->GetMonitor(cutNode);
  }
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
std::string vtkSlicerVolumeCuttingLogic::GetContactSegmentID(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  const int label = field ? field->GetContactLabel() : 0;
  const std::vector<std::string>& shieldedIds = this->ShieldedSegments[cutNode->GetID()];
  return label > 0 && label <= static_cast<int>(shieldedIds.size()) ? shieldedIds[label - 1] : std::string();
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkSlicerVolumeCuttingLogic::CreateSegmentLabelMap(
  vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds, vtkImageData* labels)
{
  return vtkSlicerVolumeCuttingSegmentImages::CreateLabelMap(
    cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr, cutNode ? cutNode->GetSegmentationNode() : nullptr, segmentIds, labels);
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::CreateSegmentFractionOnAnatomyGrid(
  vtkMRMLVolumeCutNode* cutNode, const std::string& segmentId, vtkImageData* fraction)
{
  return vtkSlicerVolumeCuttingSegmentImages::CreateFraction(
    cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr, cutNode ? cutNode->GetSegmentationNode() : nullptr, segmentId, fraction);
}
