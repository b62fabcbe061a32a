/*==============================================================================

  VolumeCutting
  Licensed under the Apache License, Version 2.0 (the "License");

==============================================================================*/

#include "vtkMRMLVolumeCutToolDisplayableManager.h"

#include "vtkMRMLVolumeCutToolDisplayNode.h"
#include "vtkMRMLVolumeCutToolNode.h"

#include <vtkMRMLModelNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLTransformNode.h>
#include <vtkMRMLViewNode.h>

#include <vtkActor.h>
#include <vtkCubeSource.h>
#include <vtkCylinderSource.h>
#include <vtkIntArray.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkSphereSource.h>
#include <vtkTransform.h>
#include <vtkTransformPolyDataFilter.h>

#include <algorithm>
#include <map>

vtkStandardNewMacro(vtkMRMLVolumeCutToolDisplayableManager);

namespace
{
/// Length (mm) of the shaft drawn behind the cutting part.
constexpr double ShaftLength = 40.0;

/// A cylinder of VTK's source (along y, centred) turned onto z.
vtkSmartPointer<vtkPolyData> CylinderAlongZ(double radius, double length, double centerZ)
{
  vtkNew<vtkCylinderSource> cylinder;
  cylinder->SetRadius(radius);
  cylinder->SetHeight(length);
  cylinder->SetResolution(40);
  vtkNew<vtkTransform> turn;
  turn->Translate(0.0, 0.0, centerZ);
  turn->RotateX(90.0);
  vtkNew<vtkTransformPolyDataFilter> filter;
  filter->SetInputConnection(cylinder->GetOutputPort());
  filter->SetTransform(turn);
  filter->Update();
  return filter->GetOutput();
}

/// The cutting part in the tool's frame, as vtkMRMLVolumeCutToolNode defines it.
vtkSmartPointer<vtkPolyData> ToolSurface(vtkMRMLVolumeCutToolNode* tool)
{
  switch (tool->GetShape())
  {
    case vtkMRMLVolumeCutToolNode::Sphere:
    {
      vtkNew<vtkSphereSource> sphere;
      sphere->SetRadius(0.5 * tool->GetDiameter());
      sphere->SetThetaResolution(32);
      sphere->SetPhiResolution(24);
      sphere->Update();
      return sphere->GetOutput();
    }
    case vtkMRMLVolumeCutToolNode::Cylinder:
      return CylinderAlongZ(0.5 * tool->GetDiameter(), tool->GetLength(), 0.0);
    case vtkMRMLVolumeCutToolNode::DiskSaw:
      return CylinderAlongZ(0.5 * tool->GetDiameter(), tool->GetThickness(), 0.0);
    case vtkMRMLVolumeCutToolNode::Blade:
    {
      vtkNew<vtkCubeSource> box;
      box->SetXLength(tool->GetWidth());
      box->SetYLength(tool->GetThickness());
      box->SetZLength(tool->GetLength());
      box->Update();
      return box->GetOutput();
    }
    case vtkMRMLVolumeCutToolNode::Mesh:
    {
      vtkMRMLModelNode* model = tool->GetMeshModelNode();
      auto surface = vtkSmartPointer<vtkPolyData>::New();
      if (model && model->GetPolyData())
      {
        surface->DeepCopy(model->GetPolyData());
      }
      return surface;
    }
    default:
      return vtkSmartPointer<vtkPolyData>::New();
  }
}

/// How far the cutting part reaches along +z, where the shaft starts.
double ShaftStart(vtkMRMLVolumeCutToolNode* tool)
{
  switch (tool->GetShape())
  {
    case vtkMRMLVolumeCutToolNode::Cylinder:
    case vtkMRMLVolumeCutToolNode::Blade:
      return 0.5 * tool->GetLength();
    case vtkMRMLVolumeCutToolNode::DiskSaw:
      return 0.5 * tool->GetThickness();
    default:
      return tool->GetCuttingRadius();
  }
}
} // namespace

//---------------------------------------------------------------------------
struct vtkMRMLVolumeCutToolDisplayableManager::Internals
{
  struct Pipeline
  {
    vtkSmartPointer<vtkActor> Tool;
    vtkSmartPointer<vtkActor> Shaft;
    vtkMTimeType GeometryTime = 0;
  };
  std::map<vtkMRMLVolumeCutToolNode*, Pipeline> Pipelines;
};

//---------------------------------------------------------------------------
vtkMRMLVolumeCutToolDisplayableManager::vtkMRMLVolumeCutToolDisplayableManager()
  : Impl(new Internals)
{
}

//---------------------------------------------------------------------------
vtkMRMLVolumeCutToolDisplayableManager::~vtkMRMLVolumeCutToolDisplayableManager() = default;

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Tools shown: " << this->Impl->Pipelines.size() << "\n";
}

//---------------------------------------------------------------------------
vtkActor* vtkMRMLVolumeCutToolDisplayableManager::GetToolActor(vtkMRMLVolumeCutToolNode* toolNode)
{
  auto found = this->Impl->Pipelines.find(toolNode);
  return found == this->Impl->Pipelines.end() ? nullptr : found->second.Tool.GetPointer();
}

//---------------------------------------------------------------------------
vtkActor* vtkMRMLVolumeCutToolDisplayableManager::GetShaftActor(vtkMRMLVolumeCutToolNode* toolNode)
{
  auto found = this->Impl->Pipelines.find(toolNode);
  return found == this->Impl->Pipelines.end() ? nullptr : found->second.Shaft.GetPointer();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::SetMRMLSceneInternal(vtkMRMLScene* newScene)
{
  vtkNew<vtkIntArray> events;
  events->InsertNextValue(vtkMRMLScene::NodeAddedEvent);
  events->InsertNextValue(vtkMRMLScene::NodeRemovedEvent);
  events->InsertNextValue(vtkMRMLScene::EndCloseEvent);
  events->InsertNextValue(vtkMRMLScene::EndBatchProcessEvent);
  this->SetAndObserveMRMLSceneEventsInternal(newScene, events);
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::OnMRMLSceneNodeAdded(vtkMRMLNode* node)
{
  vtkMRMLVolumeCutToolNode* toolNode = vtkMRMLVolumeCutToolNode::SafeDownCast(node);
  if (!toolNode || this->GetMRMLScene()->IsBatchProcessing())
  {
    return;
  }
  // UpdateFromMRMLScene (after every batch, import or view change) passes known tools again: observing
  // them twice made the observer manager warn once per tool and event.
  if (!this->Impl->Pipelines.count(toolNode))
  {
    vtkNew<vtkIntArray> events;
    events->InsertNextValue(vtkCommand::ModifiedEvent);
    events->InsertNextValue(vtkMRMLVolumeCutToolNode::ToolGeometryModifiedEvent);
    events->InsertNextValue(vtkMRMLTransformableNode::TransformModifiedEvent);
    events->InsertNextValue(vtkMRMLDisplayableNode::DisplayModifiedEvent);
    vtkObserveMRMLNodeEventsMacro(toolNode, events);
  }
  this->UpdatePipeline(toolNode);
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::OnMRMLSceneNodeRemoved(vtkMRMLNode* node)
{
  vtkMRMLVolumeCutToolNode* toolNode = vtkMRMLVolumeCutToolNode::SafeDownCast(node);
  if (toolNode)
  {
    vtkUnObserveMRMLNodeMacro(toolNode);
    this->RemovePipeline(toolNode);
  }
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::OnMRMLSceneEndClose()
{
  while (!this->Impl->Pipelines.empty())
  {
    this->RemovePipeline(this->Impl->Pipelines.begin()->first);
  }
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::UpdateFromMRMLScene()
{
  vtkMRMLScene* scene = this->GetMRMLScene();
  if (!scene)
  {
    return;
  }
  std::vector<vtkMRMLNode*> tools;
  scene->GetNodesByClass("vtkMRMLVolumeCutToolNode", tools);
  for (vtkMRMLNode* node : tools)
  {
    this->OnMRMLSceneNodeAdded(node);
  }
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::ProcessMRMLNodesEvents(vtkObject* caller, unsigned long event, void* callData)
{
  vtkMRMLVolumeCutToolNode* toolNode = vtkMRMLVolumeCutToolNode::SafeDownCast(caller);
  if (toolNode && this->Impl->Pipelines.count(toolNode))
  {
    this->UpdatePipeline(toolNode);
    this->RequestRender();
    return;
  }
  this->Superclass::ProcessMRMLNodesEvents(caller, event, callData);
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::RemovePipeline(vtkMRMLVolumeCutToolNode* toolNode)
{
  auto found = this->Impl->Pipelines.find(toolNode);
  if (found == this->Impl->Pipelines.end())
  {
    return;
  }
  this->GetRenderer()->RemoveActor(found->second.Tool);
  this->GetRenderer()->RemoveActor(found->second.Shaft);
  this->Impl->Pipelines.erase(found);
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayableManager::UpdatePipeline(vtkMRMLVolumeCutToolNode* toolNode)
{
  Internals::Pipeline& pipeline = this->Impl->Pipelines[toolNode];
  if (!pipeline.Tool)
  {
    for (vtkSmartPointer<vtkActor>* actor : { &pipeline.Tool, &pipeline.Shaft })
    {
      *actor = vtkSmartPointer<vtkActor>::New();
      vtkNew<vtkPolyDataMapper> mapper;
      (*actor)->SetMapper(mapper);
      (*actor)->SetPickable(false);
      this->GetRenderer()->AddActor(*actor);
    }
  }
  // Geometry only when the tool's shape, sizes or mesh changed.
  vtkMRMLModelNode* model = toolNode->GetMeshModelNode();
  vtkMTimeType geometryTime = toolNode->GetMTime();
  if (model && model->GetPolyData())
  {
    geometryTime = std::max(geometryTime, model->GetPolyData()->GetMTime());
  }
  if (geometryTime != pipeline.GeometryTime)
  {
    vtkPolyDataMapper::SafeDownCast(pipeline.Tool->GetMapper())->SetInputData(ToolSurface(toolNode));
    const double start = ShaftStart(toolNode);
    vtkPolyDataMapper::SafeDownCast(pipeline.Shaft->GetMapper())
      ->SetInputData(CylinderAlongZ(0.25 * std::max(0.5, std::min(toolNode->GetDiameter(), 3.0)), ShaftLength, start + 0.5 * ShaftLength));
    pipeline.GeometryTime = geometryTime;
  }
  // The pose: the tool's parent transform, to world.
  vtkNew<vtkMatrix4x4> toolToWorld;
  if (vtkMRMLTransformNode* transform = toolNode->GetParentTransformNode())
  {
    transform->GetMatrixTransformToWorld(toolToWorld);
  }
  vtkMRMLVolumeCutToolDisplayNode* display = toolNode->GetVolumeCutToolDisplayNode();
  vtkMRMLViewNode* view = this->GetMRMLViewNode();
  const bool visible = display && display->GetVisibility() && display->GetVisibility3D() && (!view || display->IsDisplayableInView(view->GetID()));
  for (vtkActor* actor : { pipeline.Tool.GetPointer(), pipeline.Shaft.GetPointer() })
  {
    actor->SetUserMatrix(toolToWorld);
    if (display)
    {
      actor->GetProperty()->SetColor(display->GetColor());
      actor->GetProperty()->SetOpacity(display->GetOpacity());
    }
  }
  pipeline.Shaft->GetProperty()->SetColor(0.75, 0.75, 0.78);
  pipeline.Tool->SetVisibility(visible);
  pipeline.Shaft->SetVisibility(visible && display->GetShowAxis());
}
