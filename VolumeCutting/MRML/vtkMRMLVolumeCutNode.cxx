/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutStorageNode.h"

// VolumeCutting includes
#include <vtkVolumeCutField.h>

// MRML includes
#include <vtkMRMLNodePropertyMacros.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkSegmentation.h>

// VTK includes
#include <vtkCommand.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>

// STD includes
#include <algorithm>

const char* vtkMRMLVolumeCutNode::AnatomyVolumeReferenceRole = "anatomyVolume";
const char* vtkMRMLVolumeCutNode::SegmentationReferenceRole = "segmentation";
const char* vtkMRMLVolumeCutNode::ActiveToolReferenceRole = "activeTool";

namespace
{
bool Contains(const std::vector<std::string>& ids, const std::string& id)
{
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}

bool Erase(std::vector<std::string>& ids, const std::string& id)
{
  auto newEnd = std::remove(ids.begin(), ids.end(), id);
  const bool erased = newEnd != ids.end();
  ids.erase(newEnd, ids.end());
  return erased;
}

/// Unique IDs in their first order, empty IDs dropped.
std::vector<std::string> Normalized(const std::vector<std::string>& ids)
{
  std::vector<std::string> unique;
  for (const std::string& id : ids)
  {
    if (!id.empty() && !Contains(unique, id))
    {
      unique.push_back(id);
    }
  }
  return unique;
}
} // namespace

//----------------------------------------------------------------------------
vtkMRMLNodeNewMacro(vtkMRMLVolumeCutNode);

//----------------------------------------------------------------------------
vtkMRMLVolumeCutNode::vtkMRMLVolumeCutNode()
{
  // The cut parameters are user edits worth undoing; the referenced anatomy is
  // never changed by this node, so restoring a state only restores IDs.
  this->SetUndoEnabled(true);

  vtkNew<vtkIntArray> volumeEvents;
  volumeEvents->InsertNextValue(vtkMRMLVolumeNode::ImageDataModifiedEvent);
  this->AddNodeReferenceRole(AnatomyVolumeReferenceRole, "anatomyVolumeRef", volumeEvents);

  vtkNew<vtkIntArray> segmentationEvents;
  segmentationEvents->InsertNextValue(vtkSegmentation::SourceRepresentationModified);
  segmentationEvents->InsertNextValue(vtkSegmentation::SegmentAdded);
  segmentationEvents->InsertNextValue(vtkSegmentation::SegmentRemoved);
  this->AddNodeReferenceRole(SegmentationReferenceRole, "segmentationRef", segmentationEvents);

  this->AddNodeReferenceRole(ActiveToolReferenceRole, "activeToolRef");
}

//----------------------------------------------------------------------------
vtkMRMLVolumeCutNode::~vtkMRMLVolumeCutNode()
{
  vtkSetAndObserveMRMLObjectMacro(this->CutField, nullptr);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetCutField(vtkVolumeCutField* field)
{
  if (field == this->CutField)
  {
    return;
  }
  vtkSetAndObserveMRMLObjectMacro(this->CutField, field);
  this->StorableModified();
  this->Modified();
}

//----------------------------------------------------------------------------
vtkVolumeCutField* vtkMRMLVolumeCutNode::GetPreviewCutField()
{
  return this->PreviewCutField;
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetPreviewCutField(vtkVolumeCutField* field)
{
  if (field == this->PreviewCutField)
  {
    return;
  }
  this->PreviewCutField = field;
  this->InvokeCustomModifiedEvent(CutModifiedEvent);
}

//----------------------------------------------------------------------------
vtkMRMLStorageNode* vtkMRMLVolumeCutNode::CreateDefaultStorageNode()
{
  return vtkMRMLVolumeCutStorageNode::New();
}

//----------------------------------------------------------------------------
std::string vtkMRMLVolumeCutNode::GetDefaultStorageNodeClassName(const char* vtkNotUsed(filename))
{
  return "vtkMRMLVolumeCutStorageNode";
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::WriteXML(ostream& of, int nIndent)
{
  Superclass::WriteXML(of, nIndent);
  vtkMRMLWriteXMLBeginMacro(of);
  // Protected first: reading sets them first, so a cuttable ID is never
  // checked against the previous protected list.
  vtkMRMLWriteXMLStdStringVectorMacro(protectedSegmentIDs, ProtectedSegmentIDs, std::vector);
  vtkMRMLWriteXMLStdStringVectorMacro(cuttableSegmentIDs, CuttableSegmentIDs, std::vector);
  vtkMRMLWriteXMLStdStringVectorMacro(materialSegmentIDs, MaterialSegmentIDs, std::vector);
  vtkMRMLWriteXMLIntMacro(subVoxelFactor, SubVoxelFactor);
  vtkMRMLWriteXMLFloatMacro(surfaceIsoValue, SurfaceIsoValue);
  vtkMRMLWriteXMLBooleanMacro(thinBoneShading, ThinBoneShading);
  vtkMRMLWriteXMLFloatMacro(thinBoneThickness, ThinBoneThickness);
  vtkMRMLWriteXMLBooleanMacro(ambientOcclusion, AmbientOcclusion);
  vtkMRMLWriteXMLFloatMacro(labelSmoothing, LabelSmoothing);
  vtkMRMLWriteXMLBooleanMacro(sliceOutlineVisibility, SliceOutlineVisibility);
  vtkMRMLWriteXMLBooleanMacro(sliceFillVisibility, SliceFillVisibility);
  vtkMRMLWriteXMLFloatMacro(sliceFillOpacity, SliceFillOpacity);
  vtkMRMLWriteXMLVectorMacro(sliceColor, SliceColor, double, 3);
  vtkMRMLWriteXMLFloatMacro(sliceOutlineThickness, SliceOutlineThickness);
  vtkMRMLWriteXMLEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::ReadXMLAttributes(const char** atts)
{
  MRMLNodeModifyBlocker blocker(this);
  Superclass::ReadXMLAttributes(atts);
  vtkMRMLReadXMLBeginMacro(atts);
  vtkMRMLReadXMLStdStringVectorMacro(protectedSegmentIDs, ProtectedSegmentIDs, std::vector);
  vtkMRMLReadXMLStdStringVectorMacro(cuttableSegmentIDs, CuttableSegmentIDs, std::vector);
  vtkMRMLReadXMLStdStringVectorMacro(materialSegmentIDs, MaterialSegmentIDs, std::vector);
  vtkMRMLReadXMLIntMacro(subVoxelFactor, SubVoxelFactor);
  vtkMRMLReadXMLFloatMacro(surfaceIsoValue, SurfaceIsoValue);
  vtkMRMLReadXMLBooleanMacro(thinBoneShading, ThinBoneShading);
  vtkMRMLReadXMLFloatMacro(thinBoneThickness, ThinBoneThickness);
  vtkMRMLReadXMLBooleanMacro(ambientOcclusion, AmbientOcclusion);
  vtkMRMLReadXMLFloatMacro(labelSmoothing, LabelSmoothing);
  vtkMRMLReadXMLBooleanMacro(sliceOutlineVisibility, SliceOutlineVisibility);
  vtkMRMLReadXMLBooleanMacro(sliceFillVisibility, SliceFillVisibility);
  vtkMRMLReadXMLFloatMacro(sliceFillOpacity, SliceFillOpacity);
  vtkMRMLReadXMLVectorMacro(sliceColor, SliceColor, double, 3);
  vtkMRMLReadXMLFloatMacro(sliceOutlineThickness, SliceOutlineThickness);
  vtkMRMLReadXMLEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::CopyContent(vtkMRMLNode* anode, bool deepCopy /*=true*/)
{
  MRMLNodeModifyBlocker blocker(this);
  Superclass::CopyContent(anode, deepCopy);
  vtkMRMLVolumeCutNode* source = vtkMRMLVolumeCutNode::SafeDownCast(anode);
  if (source)
  {
    if (deepCopy && source->GetCutField())
    {
      vtkNew<vtkVolumeCutField> field;
      field->DeepCopy(source->GetCutField());
      this->SetCutField(field);
    }
    else
    {
      // Shallow copies (scene undo) share the field: strokes have their own undo.
      this->SetCutField(source->GetCutField());
    }
  }
  vtkMRMLCopyBeginMacro(anode);
  // Protected first, so that an ID moving from protected to cuttable in the
  // source is not rejected against this node's old protected list.
  vtkMRMLCopyStdStringVectorMacro(ProtectedSegmentIDs);
  vtkMRMLCopyStdStringVectorMacro(CuttableSegmentIDs);
  vtkMRMLCopyStdStringVectorMacro(MaterialSegmentIDs);
  vtkMRMLCopyIntMacro(SubVoxelFactor);
  vtkMRMLCopyFloatMacro(SurfaceIsoValue);
  vtkMRMLCopyBooleanMacro(ThinBoneShading);
  vtkMRMLCopyFloatMacro(ThinBoneThickness);
  vtkMRMLCopyBooleanMacro(AmbientOcclusion);
  vtkMRMLCopyFloatMacro(LabelSmoothing);
  vtkMRMLCopyBooleanMacro(SliceOutlineVisibility);
  vtkMRMLCopyBooleanMacro(SliceFillVisibility);
  vtkMRMLCopyFloatMacro(SliceFillOpacity);
  vtkMRMLCopyVectorMacro(SliceColor, double, 3);
  vtkMRMLCopyFloatMacro(SliceOutlineThickness);
  vtkMRMLCopyEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::PrintSelf(ostream& os, vtkIndent indent)
{
  Superclass::PrintSelf(os, indent);
  vtkMRMLPrintBeginMacro(os, indent);
  vtkMRMLPrintStdStringVectorMacro(CuttableSegmentIDs, std::vector);
  vtkMRMLPrintStdStringVectorMacro(ProtectedSegmentIDs, std::vector);
  vtkMRMLPrintStdStringVectorMacro(MaterialSegmentIDs, std::vector);
  vtkMRMLPrintIntMacro(SubVoxelFactor);
  vtkMRMLPrintFloatMacro(SurfaceIsoValue);
  vtkMRMLPrintBooleanMacro(ThinBoneShading);
  vtkMRMLPrintFloatMacro(ThinBoneThickness);
  vtkMRMLPrintBooleanMacro(AmbientOcclusion);
  vtkMRMLPrintFloatMacro(LabelSmoothing);
  vtkMRMLPrintBooleanMacro(SliceOutlineVisibility);
  vtkMRMLPrintBooleanMacro(SliceFillVisibility);
  vtkMRMLPrintFloatMacro(SliceFillOpacity);
  vtkMRMLPrintVectorMacro(SliceColor, double, 3);
  vtkMRMLPrintFloatMacro(SliceOutlineThickness);
  vtkMRMLPrintEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::ProcessMRMLEvents(vtkObject* caller, unsigned long event, void* callData)
{
  Superclass::ProcessMRMLEvents(caller, event, callData);
  if (caller == nullptr)
  {
    return;
  }
  if (caller == this->CutField && event == vtkCommand::ModifiedEvent)
  {
    // Cuts are data: the scene must save the node again.
    this->StorableModified();
    return;
  }
  if (caller == this->GetSegmentationNode() && event == vtkSegmentation::SegmentRemoved)
  {
    const char* segmentId = static_cast<const char*>(callData);
    if (segmentId)
    {
      this->RemoveSegmentRoles(segmentId);
    }
    this->InvokeCustomModifiedEvent(InputDataModifiedEvent);
  }
  else if ((caller == this->GetSegmentationNode() && (event == vtkSegmentation::SourceRepresentationModified || event == vtkSegmentation::SegmentAdded))
           || (caller == this->GetAnatomyVolumeNode() && event == vtkMRMLVolumeNode::ImageDataModifiedEvent))
  {
    this->InvokeCustomModifiedEvent(InputDataModifiedEvent);
  }
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetAndObserveAnatomyVolumeNodeID(const char* nodeId)
{
  this->SetAndObserveNodeReferenceID(AnatomyVolumeReferenceRole, nodeId);
}

//----------------------------------------------------------------------------
const char* vtkMRMLVolumeCutNode::GetAnatomyVolumeNodeID()
{
  return this->GetNodeReferenceID(AnatomyVolumeReferenceRole);
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkMRMLVolumeCutNode::GetAnatomyVolumeNode()
{
  return vtkMRMLScalarVolumeNode::SafeDownCast(this->GetNodeReference(AnatomyVolumeReferenceRole));
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetAndObserveSegmentationNodeID(const char* nodeId)
{
  this->SetAndObserveNodeReferenceID(SegmentationReferenceRole, nodeId);
}

//----------------------------------------------------------------------------
const char* vtkMRMLVolumeCutNode::GetSegmentationNodeID()
{
  return this->GetNodeReferenceID(SegmentationReferenceRole);
}

//----------------------------------------------------------------------------
vtkMRMLSegmentationNode* vtkMRMLVolumeCutNode::GetSegmentationNode()
{
  return vtkMRMLSegmentationNode::SafeDownCast(this->GetNodeReference(SegmentationReferenceRole));
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetAndObserveActiveToolNodeID(const char* nodeId)
{
  this->SetAndObserveNodeReferenceID(ActiveToolReferenceRole, nodeId);
}

//----------------------------------------------------------------------------
const char* vtkMRMLVolumeCutNode::GetActiveToolNodeID()
{
  return this->GetNodeReferenceID(ActiveToolReferenceRole);
}

//----------------------------------------------------------------------------
vtkMRMLNode* vtkMRMLVolumeCutNode::GetActiveToolNode()
{
  return this->GetNodeReference(ActiveToolReferenceRole);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetCuttableSegmentIDs(const std::vector<std::string>& segmentIds)
{
  std::vector<std::string> cuttable = Normalized(segmentIds);
  for (const std::string& id : this->ProtectedSegmentIDs)
  {
    if (Erase(cuttable, id))
    {
      vtkWarningMacro("SetCuttableSegmentIDs: segment '" << id << "' is protected and stays protected");
    }
  }
  if (cuttable == this->CuttableSegmentIDs)
  {
    return;
  }
  this->CuttableSegmentIDs = cuttable;
  this->Modified();
  this->InvokeCustomModifiedEvent(SegmentRolesModifiedEvent);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetMaterialSegmentIDs(const std::vector<std::string>& segmentIds)
{
  // In the given order: the first segment gives the material its colour.
  const std::vector<std::string> material = Normalized(segmentIds);
  if (material == this->MaterialSegmentIDs)
  {
    return;
  }
  this->MaterialSegmentIDs = material;
  this->Modified();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetProtectedSegmentIDs(const std::vector<std::string>& segmentIds)
{
  std::vector<std::string> protectedIds = Normalized(segmentIds);
  std::vector<std::string> cuttable = this->CuttableSegmentIDs;
  for (const std::string& id : protectedIds)
  {
    Erase(cuttable, id);
  }
  if (protectedIds == this->ProtectedSegmentIDs && cuttable == this->CuttableSegmentIDs)
  {
    return;
  }
  this->ProtectedSegmentIDs = protectedIds;
  this->CuttableSegmentIDs = cuttable;
  this->Modified();
  this->InvokeCustomModifiedEvent(SegmentRolesModifiedEvent);
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutNode::CheckSegmentExists(const std::string& segmentId, const char* caller)
{
  vtkMRMLSegmentationNode* segmentationNode = this->GetSegmentationNode();
  if (!segmentationNode || !segmentationNode->GetSegmentation())
  {
    vtkErrorMacro(<< caller << ": no segmentation is referenced, cannot set the role of segment '" << segmentId << "'");
    return false;
  }
  if (!segmentationNode->GetSegmentation()->GetSegment(segmentId))
  {
    vtkErrorMacro(<< caller << ": segmentation '" << (segmentationNode->GetName() ? segmentationNode->GetName() : "") << "' has no segment with ID '" << segmentId << "'");
    return false;
  }
  return true;
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutNode::SetSegmentCuttable(const std::string& segmentId, bool cuttable)
{
  if (!this->CheckSegmentExists(segmentId, "SetSegmentCuttable"))
  {
    return false;
  }
  MRMLNodeModifyBlocker blocker(this);
  std::vector<std::string> cuttableIds = this->CuttableSegmentIDs;
  if (cuttable)
  {
    std::vector<std::string> protectedIds = this->ProtectedSegmentIDs;
    Erase(protectedIds, segmentId);
    this->SetProtectedSegmentIDs(protectedIds);
    cuttableIds.push_back(segmentId);
  }
  else
  {
    Erase(cuttableIds, segmentId);
  }
  this->SetCuttableSegmentIDs(cuttableIds);
  return true;
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutNode::SetSegmentProtected(const std::string& segmentId, bool isProtected)
{
  if (!this->CheckSegmentExists(segmentId, "SetSegmentProtected"))
  {
    return false;
  }
  std::vector<std::string> protectedIds = this->ProtectedSegmentIDs;
  if (isProtected)
  {
    protectedIds.push_back(segmentId);
  }
  else
  {
    Erase(protectedIds, segmentId);
  }
  this->SetProtectedSegmentIDs(protectedIds);
  return true;
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutNode::IsSegmentCuttable(const std::string& segmentId) const
{
  return Contains(this->CuttableSegmentIDs, segmentId);
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutNode::IsSegmentProtected(const std::string& segmentId) const
{
  return Contains(this->ProtectedSegmentIDs, segmentId);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::RemoveSegmentRoles(const std::string& segmentId)
{
  std::vector<std::string> cuttable = this->CuttableSegmentIDs;
  std::vector<std::string> protectedIds = this->ProtectedSegmentIDs;
  const bool changed = Erase(cuttable, segmentId) | Erase(protectedIds, segmentId);
  if (!changed)
  {
    return;
  }
  MRMLNodeModifyBlocker blocker(this);
  this->SetProtectedSegmentIDs(protectedIds);
  this->SetCuttableSegmentIDs(cuttable);
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutNode::IsValidSubVoxelFactor(int factor)
{
  return factor == 1 || factor == 2 || factor == 4;
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutNode::SetSubVoxelFactor(int factor)
{
  if (!IsValidSubVoxelFactor(factor))
  {
    vtkErrorMacro("SetSubVoxelFactor: " << factor << " is not supported; use 1, 2 or 4");
    return;
  }
  if (factor == this->SubVoxelFactor)
  {
    return;
  }
  this->SubVoxelFactor = factor;
  this->Modified();
}
