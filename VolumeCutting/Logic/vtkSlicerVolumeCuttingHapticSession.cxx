/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingHapticSession.h"
#include "vtkSlicerVolumeCuttingLogic.h"

// VolumeCutting includes
#include "vtkHapticDevice.h"
#include "vtkHapticForceModel.h"
#include "vtkHapticLoop.h"
#include "vtkHapticVibration.h"
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutNerveMonitor.h"

// MRML includes
#include <vtkMRMLMarkupsNode.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLTransformNode.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkObjectFactory.h>

vtkStandardNewMacro(vtkSlicerVolumeCuttingHapticSession);

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingHapticSession::vtkSlicerVolumeCuttingHapticSession() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingHapticSession::~vtkSlicerVolumeCuttingHapticSession()
{
  this->Loop->Stop();
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingHapticSession::SetLogic(vtkSlicerVolumeCuttingLogic* logic)
{
  this->Logic = logic;
  this->Modified();
}

vtkSlicerVolumeCuttingLogic* vtkSlicerVolumeCuttingHapticSession::GetLogic()
{
  return this->Logic;
}

vtkHapticLoop* vtkSlicerVolumeCuttingHapticSession::GetLoop()
{
  return this->Loop;
}

vtkHapticForceModel* vtkSlicerVolumeCuttingHapticSession::GetForceModel()
{
  return this->ForceModel;
}

vtkMRMLVolumeCutNode* vtkSlicerVolumeCuttingHapticSession::GetCutNode()
{
  return this->CutNode;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingHapticSession::IsRunning() const
{
  return this->Loop->IsRunning();
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingHapticSession::SetGuideLine(vtkMRMLMarkupsNode* line)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("SetGuideLine: stop the haptic session first; the guide is read by the haptic thread");
    return false;
  }
  if (!line || line->GetNumberOfControlPoints() < 2)
  {
    vtkErrorMacro("SetGuideLine: the guide needs a markups line with two control points");
    return false;
  }
  double start[3];
  double end[3];
  line->GetNthControlPointPositionWorld(0, start);
  line->GetNthControlPointPositionWorld(1, end);
  const double direction[3] = { end[0] - start[0], end[1] - start[1], end[2] - start[2] };
  if (!(vtkMath::Norm(direction) > 1e-6))
  {
    vtkErrorMacro("SetGuideLine: the two points of '" << (line->GetName() ? line->GetName() : "") << "' coincide; they give no axis");
    return false;
  }
  return this->ForceModel->SetGuideAxis(start, direction);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingHapticSession::RemoveGuide()
{
  if (this->IsRunning())
  {
    vtkErrorMacro("RemoveGuide: stop the haptic session first");
    return;
  }
  this->ForceModel->RemoveGuide();
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingHapticSession::Start(vtkMRMLVolumeCutNode* cutNode, vtkHapticDevice* device, vtkHapticDevice* footSwitch)
{
  if (this->IsRunning())
  {
    vtkErrorMacro("Start: the haptic session is running already; stop it first");
    return false;
  }
  vtkSlicerVolumeCuttingLogic* logic = this->Logic;
  if (!logic || !cutNode || !device)
  {
    vtkErrorMacro("Start: " << (!logic ? "no module logic is set" : !cutNode ? "no volume-cut node was given" : "no device was given"));
    return false;
  }
  const std::string nodeName = cutNode->GetName() ? cutNode->GetName() : "";
  vtkMRMLVolumeCutToolNode* toolNode = vtkSlicerVolumeCuttingLogic::GetActiveTool(cutNode);
  if (!toolNode)
  {
    vtkErrorMacro("Start: the volume-cut node '" << nodeName << "' has no active tool node; choose the tool to drill with first");
    return false;
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  // The field as the logic keeps it: on the anatomy's grid, with the tool's shield.
  vtkVolumeCutField* field = logic->GetCutField(cutNode);
  if (!anatomy || !anatomy->GetImageData() || !field)
  {
    vtkErrorMacro("Start: the volume-cut node '" << nodeName << "' has no anatomy or cut field (see the error above)");
    return false;
  }
  if (!device->IsConnected() && !device->Open())
  {
    vtkErrorMacro("Start: the haptic device could not be opened (see the error above)");
    return false;
  }
  if (footSwitch && !footSwitch->IsConnected() && !footSwitch->Open())
  {
    vtkErrorMacro("Start: the foot switch could not be opened (see the error above)");
    return false;
  }

  // What is felt is what is drawn: the CT's iso-surface minus the cut.
  vtkNew<vtkMatrix4x4> ijkToRAS;
  anatomy->GetIJKToRASMatrix(ijkToRAS);
  this->ForceModel->SetAnatomy(anatomy->GetImageData(), ijkToRAS);
  this->ForceModel->SetSurfaceIsoValue(cutNode->GetSurfaceIsoValue());
  this->ForceModel->SetCutField(field);
  if (toolNode->GetShape() == vtkMRMLVolumeCutToolNode::Sphere)
  {
    this->ForceModel->SetTool(nullptr);
    this->ForceModel->SetSphereRadius(toolNode->GetCuttingRadius());
  }
  else
  {
    vtkVolumeCutTool* tool = logic->GetCuttingTool(toolNode);
    if (!tool)
    {
      vtkErrorMacro("Start: the active tool '" << (toolNode->GetName() ? toolNode->GetName() : "") << "' does not describe a tool to cut with");
      return false;
    }
    this->ForceModel->SetTool(tool);
  }
  if (toolNode->GetBurrType() == vtkMRMLVolumeCutToolNode::Diamond)
  {
    this->ForceModel->GetVibration()->ConfigureDiamondBurr();
  }
  else
  {
    this->ForceModel->GetVibration()->ConfigureCuttingBurr();
  }

  // The device's workspace centre where the tool is now, its axes the
  // scene's; the tool keeps its orientation (a 6-DOF device turns it from there).
  vtkNew<vtkMatrix4x4> toolToRAS;
  if (vtkMRMLTransformNode* transform = toolNode->GetParentTransformNode())
  {
    transform->GetMatrixTransformToWorld(toolToRAS);
  }
  vtkNew<vtkMatrix4x4> deviceToRAS;
  vtkNew<vtkMatrix4x4> rotation;
  for (int row = 0; row < 3; ++row)
  {
    deviceToRAS->SetElement(row, row, this->DeviceScale);
    deviceToRAS->SetElement(row, 3, toolToRAS->GetElement(row, 3));
    for (int column = 0; column < 3; ++column)
    {
      rotation->SetElement(row, column, toolToRAS->GetElement(row, column));
    }
  }
  this->Loop->SetDevice(device);
  this->Loop->SetSwitchDevice(footSwitch);
  this->Loop->SetForceModel(this->ForceModel);
  this->Loop->SetCutField(field);
  this->Loop->SetToolRotation(rotation);
  // Each tick reads the monitor too; its fields are built on the logic's worker, never in a tick.
  this->Loop->SetNerveMonitor(this->Logic ? this->Logic->GetNerveMonitor(cutNode) : nullptr);
  if (!this->Loop->SetDeviceToRAS(deviceToRAS) || !this->Loop->Start())
  {
    vtkErrorMacro("Start: the haptic loop could not start (see the error above)");
    return false;
  }
  this->CutNode = cutNode;
  this->Device = device;
  this->FootSwitch = footSwitch;
  this->ReportedContactDepth = field->GetMaximumContactDepth();
  return true;
}

//----------------------------------------------------------------------------
int vtkSlicerVolumeCuttingHapticSession::Update()
{
  if (!this->CutNode)
  {
    return 0;
  }
  // Hot-plug and what the device's threads counted, reported here.
  if (this->Device)
  {
    this->Device->ProcessConnectionEvents();
  }
  if (this->FootSwitch)
  {
    this->FootSwitch->ProcessConnectionEvents();
  }
  const int cuts = this->Loop->ProcessEvents();
  // The tool where the haptic thread last put it, through the logic as any
  // pose source; only the glyph follows: the haptic thread is the field's
  // writer, and the loop's preparer builds the shield ahead of it.
  if (this->Logic && this->Loop->GetLatestToolPose(this->Pose))
  {
    this->Logic->MoveActiveTool(this->CutNode, this->Pose, vtkSlicerVolumeCuttingLogic::ToolFollow);
  }
  // The nerve monitor as the latest tick read it.
  vtkVolumeCutNerveMonitor::Reading readings[vtkHapticLoop::MaximumNerveReadings];
  const int readingCount = this->Loop->GetNerveMonitor() ? this->Loop->GetLatestNerveReadings(readings, vtkHapticLoop::MaximumNerveReadings) : -1;
  if (this->Logic && readingCount >= 0)
  {
    this->Logic->UpdateNerveMonitorWithReadings(this->CutNode, readings, readingCount);
  }
  if ((cuts > 0) != this->Drilling)
  {
    this->Drilling = cuts > 0;
    this->CutNode->InvokeCustomModifiedEvent(
      this->Drilling ? vtkMRMLVolumeCutNode::StrokeStartedEvent : vtkMRMLVolumeCutNode::StrokeEndedEvent);
  }
  if (cuts > 0)
  {
    // Views re-render; they find the bricks the haptic thread changed by their stamps.
    this->CutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::CutModifiedEvent);
  }
  const double depth = this->Loop->GetLatestContactDepth();
  if (depth > this->ReportedContactDepth)
  {
    this->ReportedContactDepth = depth;
    this->CutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::ProtectedContactEvent);
  }
  return cuts;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingHapticSession::Stop()
{
  if (!this->CutNode)
  {
    this->Loop->Stop();
    return;
  }
  this->Loop->Stop();
  this->Update();
  // The haptic thread is done with the field: the logic's tables catch up
  // (removed volume per segment, the deepest contact with a protected segment).
  if (this->Logic)
  {
    this->Logic->EndStroke(this->CutNode);
  }
  this->CutNode = nullptr;
  this->Device = nullptr;
  this->FootSwitch = nullptr;
  this->Drilling = false;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingHapticSession::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "DeviceScale: " << this->DeviceScale << "\n";
  os << indent << "Running: " << (this->IsRunning() ? "yes" : "no") << "\n";
  os << indent << "CutNode: " << (this->CutNode && this->CutNode->GetID() ? this->CutNode->GetID() : "(none)") << "\n";
}
