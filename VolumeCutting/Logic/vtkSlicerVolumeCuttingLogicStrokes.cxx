/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// Strokes from any source (mouse, haptic device, replay): sweeps of a burr
// or tool, the active tool's motion, rate-based drilling, undo and redo, and
// the events that tell views and the user. Part of vtkSlicerVolumeCuttingLogic.

#include "vtkSlicerVolumeCuttingLogic.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkSlicerVolumeCuttingToolCache.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutMaterialRemoval.h"

// MRML includes
#include <vtkMRMLLinearTransformNode.h>
#include <vtkMRMLScalarVolumeNode.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>

// STD includes
#include <cmath>

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
  return this->ToolCache->GetTool(toolNode);
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
  if (action == ToolFollow)
  {
    return true;
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
  if (this->NerveMonitoring)
  {
    this->UpdateNerveMonitor(cutNode, toolToRAS);
  }
  return accepted;
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
void vtkSlicerVolumeCuttingLogic::ResetMaterialRemoval(vtkMRMLVolumeCutNode* cutNode)
{
  if (cutNode && cutNode->GetID())
  {
    this->MaterialRemovals.erase(cutNode->GetID());
  }
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
