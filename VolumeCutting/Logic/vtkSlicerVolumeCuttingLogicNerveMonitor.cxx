/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// The virtual nerve monitor of each cut node (seed 003): which segments it
// watches, its readings at every pose and tick, its event and table.
// Part of vtkSlicerVolumeCuttingLogic.

#include "vtkSlicerVolumeCuttingLogic.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkSlicerVolumeCuttingNerveMonitors.h"
#include "vtkSlicerVolumeCuttingTables.h"
#include "vtkVolumeCutNerveMonitor.h"

// MRML includes
#include <vtkMRMLScene.h>
#include <vtkMRMLTableNode.h>

// VTK includes
#include <vtkMatrix4x4.h>

//----------------------------------------------------------------------------
vtkVolumeCutNerveMonitor* vtkSlicerVolumeCuttingLogic::GetNerveMonitor(vtkMRMLVolumeCutNode* cutNode)
{
  return this->NerveMonitoring ? this->NerveMonitors->GetMonitor(cutNode) : nullptr;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::SetMonitoredSegmentIDs(vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds)
{
  this->NerveMonitors->SetChosenSegmentIDs(cutNode, segmentIds);
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkSlicerVolumeCuttingLogic::GetMonitoredSegmentIDs(vtkMRMLVolumeCutNode* cutNode)
{
  return this->NerveMonitors->GetMonitoredSegmentIDs(cutNode);
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::WaitForNerveMonitor(vtkMRMLVolumeCutNode* cutNode)
{
  return this->NerveMonitoring && this->NerveMonitors->Wait(cutNode);
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::GetNerveMonitorTableNode(vtkMRMLVolumeCutNode* cutNode)
{
  if (!cutNode || !this->GetMRMLScene())
  {
    vtkErrorMacro("GetNerveMonitorTableNode: no volume-cut node in a scene");
    return nullptr;
  }
  return vtkSlicerVolumeCuttingTables::GetNerveMonitorTable(
    this->GetMRMLScene(), cutNode, vtkSlicerVolumeCuttingNerveMonitors::GetTableReferenceRole());
}

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingNerveMonitors* vtkSlicerVolumeCuttingLogic::GetNerveMonitors()
{
  return this->NerveMonitors;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::UpdateNerveMonitor(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* toolToRAS)
{
  vtkMRMLVolumeCutToolNode* toolNode = GetActiveTool(cutNode);
  if (!toolNode || !this->NerveMonitors->GetMonitor(cutNode))
  {
    return;
  }
  const bool sphere = toolNode->GetShape() == vtkMRMLVolumeCutToolNode::Sphere;
  vtkVolumeCutTool* tool = sphere ? nullptr : this->GetCuttingTool(toolNode);
  if (!sphere && !tool)
  {
    return; // a mesh tool without its mesh: nothing to measure with
  }
  if (this->NerveMonitors->UpdateWithTool(this->GetMRMLScene(), cutNode, tool, toolNode->GetCuttingRadius(), toolToRAS))
  {
    this->InvokeEvent(NerveMonitorLevelChangedEvent, cutNode);
  }
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::UpdateNerveMonitorWithReadings(vtkMRMLVolumeCutNode* cutNode, const void* readings, int count)
{
  if (this->NerveMonitoring &&
    this->NerveMonitors->UpdateWithReadings(
      this->GetMRMLScene(), cutNode, static_cast<const vtkVolumeCutNerveMonitor::Reading*>(readings), count))
  {
    this->InvokeEvent(NerveMonitorLevelChangedEvent, cutNode);
  }
}
