/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingSoftCutLogic.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkSlicerVolumeCuttingLogic.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutResectionEstimate.h"
#include "vtkVolumeCutResectionPlanner.h"

// MRML includes
#include <vtkMRMLMarkupsClosedCurveNode.h>
#include <vtkMRMLMarkupsCurveNode.h>
#include <vtkMRMLModelNode.h>
#include <vtkMRMLModelStorageNode.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLTableNode.h>

// VTK includes
#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkTable.h>

// STD includes
#include <cmath>
#include <sstream>

vtkStandardNewMacro(vtkSlicerVolumeCuttingSoftCutLogic);

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingSoftCutLogic::vtkSlicerVolumeCuttingSoftCutLogic() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingSoftCutLogic::~vtkSlicerVolumeCuttingSoftCutLogic() = default;

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSoftCutLogic::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NormalMode: " << this->NormalMode << "\n";
  os << indent << "SkinIsoValue: " << this->SkinIsoValue << "\n";
  os << indent << "SoftTissueRange: " << this->SoftTissueRange[0] << " " << this->SoftTissueRange[1] << "\n";
  os << indent << "StripOffset: " << this->StripOffset << "\n";
  os << indent << "MaximumDepth: " << this->MaximumDepth << "\n";
  os << indent << "SkinTolerance: " << this->SkinTolerance << "\n";
  os << indent << "Plans: " << this->Planners.size() << "\n";
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSoftCutLogic::SetVolumeCuttingLogic(vtkSlicerVolumeCuttingLogic* logic)
{
  if (this->VolumeCuttingLogic != logic)
  {
    this->VolumeCuttingLogic = logic;
    this->Modified();
  }
}

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingLogic* vtkSlicerVolumeCuttingSoftCutLogic::GetVolumeCuttingLogic()
{
  return this->VolumeCuttingLogic;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSoftCutLogic::SetMRMLSceneInternal(vtkMRMLScene* newScene)
{
  vtkNew<vtkIntArray> events;
  events->InsertNextValue(vtkMRMLScene::NodeRemovedEvent);
  events->InsertNextValue(vtkMRMLScene::EndCloseEvent);
  this->SetAndObserveMRMLSceneEventsInternal(newScene, events);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSoftCutLogic::OnMRMLSceneNodeRemoved(vtkMRMLNode* node)
{
  if (vtkMRMLVolumeCutNode::SafeDownCast(node) && node->GetID())
  {
    this->Planners.erase(node->GetID());
    this->Estimates.erase(node->GetID());
  }
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSoftCutLogic::OnMRMLSceneEndClose()
{
  this->Planners.clear();
  this->Estimates.clear();
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSoftCutLogic::Fail(const std::string& message)
{
  this->ErrorMessage = message;
  vtkErrorMacro(<< message);
  return false;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSoftCutLogic::PlanResection(vtkMRMLVolumeCutNode* cutNode, vtkMRMLMarkupsNode* outline)
{
  this->ErrorMessage.clear();
  if (!cutNode || !cutNode->GetID())
  {
    return this->Fail("PlanResection: no volume-cut node in a scene");
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  if (!anatomy || !anatomy->GetImageData() || anatomy->GetImageData()->GetNumberOfPoints() == 0)
  {
    return this->Fail(std::string("PlanResection: the volume-cut node '") + (cutNode->GetName() ? cutNode->GetName() : "") +
      "' has no anatomy volume with voxels");
  }
  if (!outline)
  {
    return this->Fail("PlanResection: no outline; draw a closed curve on the skin around the resection");
  }
  const std::string name = outline->GetName() ? outline->GetName() : "";
  if (!vtkMRMLMarkupsClosedCurveNode::SafeDownCast(outline))
  {
    return this->Fail("PlanResection: the outline '" + name + "' is " +
      (vtkMRMLMarkupsCurveNode::SafeDownCast(outline) ? "an open curve" : std::string("not a curve (") + outline->GetClassName() + ")") +
      "; draw the resection's outline as a closed curve (vtkMRMLMarkupsClosedCurveNode)");
  }
  vtkMRMLMarkupsCurveNode* curve = vtkMRMLMarkupsCurveNode::SafeDownCast(outline);
  const int controlPoints = curve->GetNumberOfDefinedControlPoints();
  if (controlPoints < 3)
  {
    return this->Fail("PlanResection: the outline '" + name + "' has " + std::to_string(controlPoints) +
      " control point(s); a closed outline needs at least 3 on the skin");
  }

  vtkNew<vtkVolumeCutResectionPlanner> planner;
  vtkNew<vtkMatrix4x4> ijkToRAS;
  anatomy->GetIJKToRASMatrix(ijkToRAS);
  planner->SetAnatomy(anatomy->GetImageData(), ijkToRAS);
  planner->SetNormalMode(this->NormalMode);
  planner->SetSkinIsoValue(this->SkinIsoValue);
  planner->SetSoftTissueRange(this->SoftTissueRange);
  planner->SetStripOffset(this->StripOffset);
  planner->SetMaximumDepth(this->MaximumDepth);
  planner->SetSkinTolerance(this->SkinTolerance);
  // The user's points first: a point placed off the skin is named as the user knows it.
  for (int index = 0; index < curve->GetNumberOfControlPoints(); ++index)
  {
    double ras[3];
    curve->GetNthControlPointPositionWorld(index, ras);
    const double distance = planner->GetDistanceToSkin(ras, this->SkinTolerance);
    if (distance > this->SkinTolerance)
    {
      if (planner->GetErrorMessage()[0])
      {
        return this->Fail(std::string("PlanResection: ") + planner->GetErrorMessage());
      }
      std::ostringstream text;
      text.precision(1);
      text << std::fixed << "PlanResection: control point " << index + 1 << " ('" << (curve->GetNthControlPointLabel(index).c_str())
           << "') of the outline '" << name << "' at RAS (" << ras[0] << ", " << ras[1] << ", " << ras[2] << ") is more than "
           << this->SkinTolerance << " mm from the skin (the CT's " << this->SkinIsoValue << " HU iso-surface); place it on the skin";
      return this->Fail(text.str());
    }
  }
  vtkPoints* curvePoints = curve->GetCurvePointsWorld();
  planner->SetOutline(curvePoints && curvePoints->GetNumberOfPoints() >= 3 ? curvePoints : nullptr);
  if (!planner->Plan())
  {
    return this->Fail(std::string("PlanResection: outline '") + name + "': " + planner->GetErrorMessage());
  }
  this->Planners[cutNode->GetID()] = planner;
  this->Estimates.erase(cutNode->GetID());
  this->ClearPreview(cutNode);
  return true;
}

//----------------------------------------------------------------------------
vtkVolumeCutResectionPlanner* vtkSlicerVolumeCuttingSoftCutLogic::GetPlanner(vtkMRMLVolumeCutNode* cutNode)
{
  if (!cutNode || !cutNode->GetID())
  {
    return nullptr;
  }
  const auto found = this->Planners.find(cutNode->GetID());
  return found == this->Planners.end() ? nullptr : found->second.GetPointer();
}

//----------------------------------------------------------------------------
vtkVolumeCutResectionPlanner* vtkSlicerVolumeCuttingSoftCutLogic::GetPlanOrFail(vtkMRMLVolumeCutNode* cutNode, const char* caller)
{
  this->ErrorMessage.clear();
  vtkVolumeCutResectionPlanner* planner = this->GetPlanner(cutNode);
  if (!planner)
  {
    this->Fail(std::string(caller) + ": no resection is planned for this volume-cut node; call PlanResection with an outline first");
  }
  return planner;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSoftCutLogic::PreviewDepth(vtkMRMLVolumeCutNode* cutNode, double depth)
{
  vtkVolumeCutResectionPlanner* planner = this->GetPlanOrFail(cutNode, "PreviewDepth");
  if (!planner)
  {
    return false;
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  int dims[3];
  anatomy->GetImageData()->GetDimensions(dims);
  vtkSmartPointer<vtkVolumeCutField> preview = cutNode->GetPreviewCutField();
  if (!preview || preview->GetSubVoxelFactor() != 1 || preview->GetDimensions()[0] != dims[0] || preview->GetDimensions()[1] != dims[1] ||
    preview->GetDimensions()[2] != dims[2])
  {
    // One sample per voxel: the preview follows the slider, the carve is exact.
    preview = vtkSmartPointer<vtkVolumeCutField>::New();
    vtkNew<vtkMatrix4x4> ijkToRAS;
    anatomy->GetIJKToRASMatrix(ijkToRAS);
    if (!preview->Initialize(dims, ijkToRAS, 1))
    {
      return this->Fail("PreviewDepth: the preview could not be made on the anatomy's grid (see the log)");
    }
  }
  // The previous depth's region is taken back (its bricks get new stamps,
  // so views recast them) and the new one written.
  vtkVolumeCutField* shield = this->VolumeCuttingLogic ? this->VolumeCuttingLogic->GetCutField(cutNode) : nullptr;
  vtkNew<vtkImageData> distances;
  vtkNew<vtkImageData> keep;
  if (!planner->BuildRegion(depth, distances, keep, shield))
  {
    return this->Fail(std::string("PreviewDepth: ") + planner->GetErrorMessage());
  }
  while (preview->GetNumberOfUndoSteps() > 0)
  {
    preview->Undo();
  }
  preview->CutSampledRegion(distances, keep);
  if (cutNode->GetPreviewCutField() != preview)
  {
    cutNode->SetPreviewCutField(preview);
  }
  else
  {
    cutNode->InvokeCustomModifiedEvent(vtkMRMLVolumeCutNode::CutModifiedEvent);
  }
  return true;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingSoftCutLogic::ClearPreview(vtkMRMLVolumeCutNode* cutNode)
{
  if (cutNode)
  {
    cutNode->SetPreviewCutField(nullptr);
  }
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSoftCutLogic::CarveResection(vtkMRMLVolumeCutNode* cutNode, double depth)
{
  vtkVolumeCutResectionPlanner* planner = this->GetPlanOrFail(cutNode, "CarveResection");
  if (!planner)
  {
    return false;
  }
  if (!this->VolumeCuttingLogic)
  {
    return this->Fail("CarveResection: no volume-cutting logic to carve through; call SetVolumeCuttingLogic first");
  }
  vtkNew<vtkImageData> distances;
  vtkNew<vtkImageData> keep;
  if (!planner->BuildRegion(depth, distances, keep))
  {
    return this->Fail(std::string("CarveResection: ") + planner->GetErrorMessage());
  }
  if (!this->VolumeCuttingLogic->CutSampledRegion(cutNode, distances, keep))
  {
    return this->Fail("CarveResection: the cut field refused the resection (see the log); nothing was carved");
  }
  this->ClearPreview(cutNode);
  return true;
}

//----------------------------------------------------------------------------
vtkVolumeCutResectionEstimate* vtkSlicerVolumeCuttingSoftCutLogic::UpdateEstimate(vtkMRMLVolumeCutNode* cutNode, double depth, const char* caller)
{
  vtkVolumeCutResectionPlanner* planner = this->GetPlanOrFail(cutNode, caller);
  if (!planner)
  {
    return nullptr;
  }
  vtkSmartPointer<vtkVolumeCutResectionEstimate>& estimate = this->Estimates[cutNode->GetID()];
  if (estimate && estimate->GetPlanner() == planner && estimate->GetDepth() == depth && estimate->GetSurface()->GetNumberOfPoints() > 0)
  {
    return estimate;
  }
  vtkNew<vtkVolumeCutResectionEstimate> updated;
  updated->SetPlanner(planner);
  updated->SetDepth(depth);
  if (!updated->Update())
  {
    this->Fail(std::string(caller) + ": " + planner->GetErrorMessage());
    return nullptr;
  }
  estimate = updated;
  return estimate;
}

//----------------------------------------------------------------------------
vtkVolumeCutResectionEstimate* vtkSlicerVolumeCuttingSoftCutLogic::GetEstimate(vtkMRMLVolumeCutNode* cutNode)
{
  if (!cutNode || !cutNode->GetID())
  {
    return nullptr;
  }
  const auto found = this->Estimates.find(cutNode->GetID());
  return found == this->Estimates.end() ? nullptr : found->second.GetPointer();
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingSoftCutLogic::MeasureResection(vtkMRMLVolumeCutNode* cutNode, double depth)
{
  vtkVolumeCutResectionEstimate* estimate = this->UpdateEstimate(cutNode, depth, "MeasureResection");
  vtkMRMLScene* scene = cutNode ? cutNode->GetScene() : nullptr;
  if (!estimate || !scene)
  {
    return nullptr;
  }
  vtkMRMLTableNode* table = vtkMRMLTableNode::SafeDownCast(cutNode->GetNodeReference(GetResectionTableReferenceRole()));
  if (!table)
  {
    const std::string name = std::string(cutNode->GetName() ? cutNode->GetName() : "VolumeCut") + " SoftCut resection";
    table = vtkMRMLTableNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLTableNode", name));
    cutNode->SetNodeReferenceID(GetResectionTableReferenceRole(), table->GetID());
  }
  vtkNew<vtkStringArray> measurement;
  measurement->SetName("Measurement");
  vtkNew<vtkDoubleArray> value;
  value->SetName("Value");
  vtkNew<vtkStringArray> unit;
  unit->SetName("Unit");
  auto row = [&](const char* what, double number, const char* units) {
    measurement->InsertNextValue(what);
    value->InsertNextValue(number);
    unit->InsertNextValue(units);
  };
  vtkVolumeCutResectionPlanner* planner = estimate->GetPlanner();
  row("Depth of cut", depth, "mm");
  row("Resected volume", estimate->GetVolume(), "mm3");
  row("Surface area", estimate->GetSurfaceArea(), "mm2");
  row("Length", estimate->GetExtents()[0], "mm");
  row("Width", estimate->GetExtents()[1], "mm");
  row("Thickness", estimate->GetExtents()[2], "mm");
  row("Outline length", planner->GetOutlineLength(), "mm");
  row("Outline area (projected)", planner->GetProjectedArea(), "mm2");
  row("Volume before smoothing", estimate->GetContourVolume(), "mm3");
  const char* axes[3] = { "R", "A", "S" };
  for (int a = 0; a < 3; ++a)
  {
    row((std::string("Frame origin ") + axes[a]).c_str(), estimate->GetFrameOrigin()[a], "mm");
  }
  const char* directions[3] = { "Length axis ", "Width axis ", "Thickness axis " };
  for (int axis = 0; axis < 3; ++axis)
  {
    double direction[3];
    estimate->GetFrameAxis(axis, direction);
    for (int a = 0; a < 3; ++a)
    {
      row((directions[axis] + std::string(axes[a])).c_str(), direction[a], "");
    }
  }
  row("Normal mode (0 local, 1 average)", planner->GetNormalMode(), "");
  vtkNew<vtkTable> content;
  content->AddColumn(measurement);
  content->AddColumn(value);
  content->AddColumn(unit);
  table->SetAndObserveTable(content);
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLModelNode* vtkSlicerVolumeCuttingSoftCutLogic::CreateResectionModel(vtkMRMLVolumeCutNode* cutNode, double depth, const char* name)
{
  vtkVolumeCutResectionEstimate* estimate = this->UpdateEstimate(cutNode, depth, "CreateResectionModel");
  vtkMRMLScene* scene = cutNode ? cutNode->GetScene() : nullptr;
  if (!estimate || !scene)
  {
    return nullptr;
  }
  const std::string modelName = name ? name : std::string(cutNode->GetName() ? cutNode->GetName() : "VolumeCut") + " SoftCut resection";
  vtkMRMLModelNode* model = vtkMRMLModelNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLModelNode", modelName));
  vtkNew<vtkPolyData> mesh;
  mesh->DeepCopy(estimate->GetSurface());
  model->SetAndObservePolyData(mesh);
  model->CreateDefaultDisplayNodes();
  return model;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingSoftCutLogic::ExportResectionToSTL(vtkMRMLVolumeCutNode* cutNode, double depth, const char* fileName)
{
  const std::string path = fileName ? fileName : "";
  if (path.size() < 5 || (path.substr(path.size() - 4) != ".stl" && path.substr(path.size() - 4) != ".STL"))
  {
    return this->Fail("ExportResectionToSTL: '" + path + "' is not an .stl file name");
  }
  vtkVolumeCutResectionEstimate* estimate = this->UpdateEstimate(cutNode, depth, "ExportResectionToSTL");
  if (!estimate)
  {
    return false;
  }
  // A model and storage node of their own, outside the scene: the file is the product.
  vtkNew<vtkMRMLModelNode> model;
  vtkNew<vtkPolyData> mesh;
  mesh->DeepCopy(estimate->GetSurface());
  model->SetAndObservePolyData(mesh);
  vtkNew<vtkMRMLModelStorageNode> storage;
  storage->SetFileName(path.c_str());
  if (!storage->WriteData(model))
  {
    return this->Fail("ExportResectionToSTL: writing '" + path + "' failed; check that its folder exists and is writable");
  }
  return true;
}
