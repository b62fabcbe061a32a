/*==============================================================================

  VolumeCutting
  Licensed under the Apache License, Version 2.0 (the "License");

==============================================================================*/

#include "vtkMRMLVolumeCutDisplayableManager.h"

#include "vtkMRMLVolumeCutNode.h"
#include "vtkSlicerVolumeCuttingLogic.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutRayCaster.h"
#include "vtkVolumeCutVolumeMapper.h"

#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationDisplayNode.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>

#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkVolume.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <sstream>

vtkStandardNewMacro(vtkMRMLVolumeCutDisplayableManager);

//---------------------------------------------------------------------------
struct vtkMRMLVolumeCutDisplayableManager::Internals
{
  struct Pipeline
  {
    vtkSmartPointer<vtkVolume> Volume;
    vtkSmartPointer<vtkVolumeCutVolumeMapper> Mapper;
    vtkSmartPointer<vtkImageData> Labels;
    vtkVolumeCutField* Field = nullptr;
    vtkVolumeCutField* PreviewField = nullptr;
    std::string LabelSource;
    std::string FractionSource;
    /// What was last given to the caster as appearances (colour, opacity,
    /// shape or iso-value, surface colour per shown segment): setting them
    /// again unchanged would still modify the caster, which then rebuilds
    /// what depends on appearances and draws the whole view again.
    std::vector<double> Appearances;
  };
  std::map<vtkMRMLVolumeCutNode*, Pipeline> Pipelines;
  std::set<vtkMRMLVolumeCutNode*> NodesInStroke;
  bool RateRaised = false;
};

//---------------------------------------------------------------------------
vtkMRMLVolumeCutDisplayableManager::vtkMRMLVolumeCutDisplayableManager()
  : Impl(new Internals)
{
}

//---------------------------------------------------------------------------
vtkMRMLVolumeCutDisplayableManager::~vtkMRMLVolumeCutDisplayableManager() = default;

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Cut nodes shown: " << this->Impl->Pipelines.size() << "\n";
}

//---------------------------------------------------------------------------
vtkVolume* vtkMRMLVolumeCutDisplayableManager::GetVolumeActor(vtkMRMLVolumeCutNode* cutNode)
{
  auto found = this->Impl->Pipelines.find(cutNode);
  return found == this->Impl->Pipelines.end() ? nullptr : found->second.Volume.GetPointer();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::SetMRMLSceneInternal(vtkMRMLScene* newScene)
{
  vtkNew<vtkIntArray> events;
  events->InsertNextValue(vtkMRMLScene::NodeAddedEvent);
  events->InsertNextValue(vtkMRMLScene::NodeRemovedEvent);
  events->InsertNextValue(vtkMRMLScene::EndCloseEvent);
  events->InsertNextValue(vtkMRMLScene::EndBatchProcessEvent);
  this->SetAndObserveMRMLSceneEventsInternal(newScene, events);
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::OnMRMLSceneNodeAdded(vtkMRMLNode* node)
{
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(node);
  if (!cutNode || this->GetMRMLScene()->IsBatchProcessing())
  {
    return;
  }
  this->ObserveCutNode(cutNode);
  this->UpdatePipeline(cutNode);
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::OnMRMLSceneNodeRemoved(vtkMRMLNode* node)
{
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(node);
  if (!cutNode)
  {
    return;
  }
  vtkUnObserveMRMLNodeMacro(cutNode);
  if (this->Impl->NodesInStroke.erase(cutNode))
  {
    this->UpdateDesiredUpdateRate();
  }
  auto found = this->Impl->Pipelines.find(cutNode);
  if (found != this->Impl->Pipelines.end())
  {
    this->GetRenderer()->RemoveVolume(found->second.Volume);
    this->Impl->Pipelines.erase(found);
    this->RequestRender();
  }
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::OnMRMLSceneEndClose()
{
  for (auto& entry : this->Impl->Pipelines)
  {
    this->GetRenderer()->RemoveVolume(entry.second.Volume);
  }
  this->Impl->Pipelines.clear();
  this->Impl->NodesInStroke.clear();
  this->UpdateDesiredUpdateRate();
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::ObserveCutNode(vtkMRMLVolumeCutNode* node)
{
  vtkNew<vtkIntArray> events;
  events->InsertNextValue(vtkCommand::ModifiedEvent);
  events->InsertNextValue(vtkMRMLVolumeCutNode::InputDataModifiedEvent);
  events->InsertNextValue(vtkMRMLVolumeCutNode::SegmentRolesModifiedEvent);
  events->InsertNextValue(vtkMRMLVolumeCutNode::CutModifiedEvent);
  events->InsertNextValue(vtkMRMLVolumeCutNode::StrokeStartedEvent);
  events->InsertNextValue(vtkMRMLVolumeCutNode::StrokeEndedEvent);
  vtkObserveMRMLNodeEventsMacro(node, events);
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::UpdateDesiredUpdateRate()
{
  vtkRenderWindow* window = this->GetRenderer() ? this->GetRenderer()->GetRenderWindow() : nullptr;
  if (!window)
  {
    return;
  }
  vtkRenderWindowInteractor* interactor = window->GetInteractor();
  if (!this->Impl->NodesInStroke.empty())
  {
    window->SetDesiredUpdateRate(interactor ? interactor->GetDesiredUpdateRate() : 15.0);
    this->Impl->RateRaised = true;
  }
  else if (this->Impl->RateRaised)
  {
    // Only a rate this manager raised is put back: a camera drag owns its own.
    window->SetDesiredUpdateRate(interactor ? interactor->GetStillUpdateRate() : 0.0001);
    this->Impl->RateRaised = false;
  }
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::UpdateFromMRMLScene()
{
  vtkMRMLScene* scene = this->GetMRMLScene();
  if (!scene)
  {
    return;
  }
  std::vector<vtkMRMLNode*> nodes;
  scene->GetNodesByClass("vtkMRMLVolumeCutNode", nodes);
  for (vtkMRMLNode* node : nodes)
  {
    if (this->Impl->Pipelines.find(vtkMRMLVolumeCutNode::SafeDownCast(node)) == this->Impl->Pipelines.end())
    {
      this->ObserveCutNode(vtkMRMLVolumeCutNode::SafeDownCast(node));
    }
    this->UpdatePipeline(vtkMRMLVolumeCutNode::SafeDownCast(node));
  }
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::ProcessMRMLNodesEvents(vtkObject* caller, unsigned long event, void* callData)
{
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(caller);
  if (!cutNode)
  {
    this->Superclass::ProcessMRMLNodesEvents(caller, event, callData);
    return;
  }
  if (event == vtkMRMLVolumeCutNode::StrokeStartedEvent || event == vtkMRMLVolumeCutNode::StrokeEndedEvent)
  {
    if (event == vtkMRMLVolumeCutNode::StrokeStartedEvent)
    {
      this->Impl->NodesInStroke.insert(cutNode);
    }
    else
    {
      this->Impl->NodesInStroke.erase(cutNode);
    }
    this->UpdateDesiredUpdateRate();
  }
  else if (event != vtkMRMLVolumeCutNode::CutModifiedEvent)
  {
    this->UpdatePipeline(cutNode);
  }
  else
  {
    // The cut field may have been created by this stroke, a preview set or cleared.
    auto found = this->Impl->Pipelines.find(cutNode);
    if (found == this->Impl->Pipelines.end() || found->second.Field != cutNode->GetCutField() ||
      found->second.PreviewField != cutNode->GetPreviewCutField())
    {
      this->UpdatePipeline(cutNode);
    }
  }
  this->RequestRender();
}

//---------------------------------------------------------------------------
void vtkMRMLVolumeCutDisplayableManager::UpdatePipeline(vtkMRMLVolumeCutNode* node)
{
  vtkRenderer* renderer = this->GetRenderer();
  if (!node || !renderer)
  {
    return;
  }
  auto& pipeline = this->Impl->Pipelines[node];
  if (!pipeline.Volume)
  {
    pipeline.Volume = vtkSmartPointer<vtkVolume>::New();
    pipeline.Mapper = vtkSmartPointer<vtkVolumeCutVolumeMapper>::New();
    pipeline.Volume->SetMapper(pipeline.Mapper);
    pipeline.Volume->SetPickable(false);
    renderer->AddVolume(pipeline.Volume);
  }
  vtkMRMLScalarVolumeNode* anatomy = node->GetAnatomyVolumeNode();
  if (!anatomy || !anatomy->GetImageData())
  {
    pipeline.Volume->SetVisibility(false);
    return;
  }
  vtkVolumeCutVolumeMapper* mapper = pipeline.Mapper;
  vtkVolumeCutRayCaster* caster = mapper->GetRayCaster();
  if (mapper->GetInput() != anatomy->GetImageData())
  {
    mapper->SetInputData(anatomy->GetImageData());
  }
  // Slicer's image data have unit spacing and no origin: IJK-to-RAS places them.
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  vtkMatrix4x4* current = pipeline.Volume->GetUserMatrix();
  bool sameMatrix = current != nullptr;
  for (int element = 0; element < 16 && sameMatrix; ++element)
  {
    sameMatrix = current->GetElement(element / 4, element % 4) == ijkToRas->GetElement(element / 4, element % 4);
  }
  if (!sameMatrix)
  {
    pipeline.Volume->SetUserMatrix(ijkToRas);
  }
  if (pipeline.Field != node->GetCutField() || pipeline.PreviewField != node->GetPreviewCutField())
  {
    // A preview is one more removed region, through the multi-field path.
    caster->RemoveAllCutFields();
    for (vtkVolumeCutField* field : { node->GetCutField(), node->GetPreviewCutField() })
    {
      if (field)
      {
        caster->AddCutField(field);
      }
    }
    pipeline.Field = node->GetCutField();
    pipeline.PreviewField = node->GetPreviewCutField();
  }
  caster->SetIsoValue(node->GetSurfaceIsoValue());
  caster->SetThinBoneShading(node->GetThinBoneShading());
  caster->SetThinBoneThickness(node->GetThinBoneThickness());
  caster->SetAmbientOcclusion(node->GetAmbientOcclusion());
  caster->SetLabelSmoothing(node->GetLabelSmoothing());

  // Segments visible in 3D, in their colours.
  vtkMRMLSegmentationNode* segmentation = node->GetSegmentationNode();
  vtkMRMLSegmentationDisplayNode* display =
    segmentation ? vtkMRMLSegmentationDisplayNode::SafeDownCast(segmentation->GetDisplayNode()) : nullptr;
  std::vector<std::string> shown;
  if (segmentation && display)
  {
    for (const std::string& id : segmentation->GetSegmentation()->GetSegmentIDs())
    {
      if (display->GetSegmentVisibility3D(id) && display->GetSegmentOpacity3D(id) > 0.0)
      {
        shown.push_back(id);
      }
    }
  }
  std::ostringstream source;
  if (segmentation)
  {
    source << segmentation->GetID() << "@" << segmentation->GetSegmentation()->GetMTime() << "/" << anatomy->GetImageData()->GetMTime();
  }
  for (const std::string& id : shown)
  {
    source << "|" << id;
  }
  if (shown.empty())
  {
    caster->SetLabelMap(nullptr);
    caster->RemoveAllSegmentAppearances();
    for (int label = 1; label <= 16 && caster->GetNumberOfSegmentFractions() > 0; ++label)
    {
      caster->SetSegmentFraction(label, nullptr);
    }
    pipeline.Labels = nullptr;
    pipeline.LabelSource.clear();
    pipeline.FractionSource.clear();
    pipeline.Appearances.clear();
  }
  else
  {
    if (pipeline.LabelSource != source.str())
    {
      pipeline.Labels = vtkSmartPointer<vtkImageData>::New();
      vtkSlicerVolumeCuttingLogic::CreateSegmentLabelMap(node, shown, pipeline.Labels);
      caster->SetLabelMap(pipeline.Labels);
      pipeline.LabelSource = source.str();
    }
    for (size_t index = 0; index < shown.size() && pipeline.LabelSource != pipeline.FractionSource; ++index)
    {
      // Segments with fractional labelmaps (up to 16) are placed at sub-voxel
      // accuracy; the others by their binary labelmap.
      vtkNew<vtkImageData> fraction;
      const bool hasFraction =
        index < 16 && vtkSlicerVolumeCuttingLogic::CreateSegmentFractionOnAnatomyGrid(node, shown[index], fraction);
      caster->SetSegmentFraction(static_cast<int>(index + 1), hasFraction ? fraction.GetPointer() : nullptr);
    }
    // Segments of one material: uncut surfaces in the colour of the first.
    const std::vector<std::string> material = node->GetMaterialSegmentIDs();
    auto first = std::find_if(material.begin(), material.end(),
      [&](const std::string& id) { return segmentation->GetSegmentation()->GetSegment(id) != nullptr; });
    double materialColor[3] = { 1.0, 1.0, 1.0 };
    if (first != material.end())
    {
      segmentation->GetSegmentation()->GetSegment(*first)->GetColor(materialColor);
    }
    constexpr size_t AppearanceSize = 9; // colour, opacity, shape, iso, surface colour
    std::vector<double> appearances;
    appearances.reserve(AppearanceSize * shown.size());
    for (const std::string& id : shown)
    {
      double color[3] = { 1.0, 1.0, 1.0 };
      segmentation->GetSegmentation()->GetSegment(id)->GetColor(color);
      const bool cuttable = node->IsSegmentCuttable(id);
      const bool ofMaterial = first != material.end() && std::find(material.begin(), material.end(), id) != material.end();
      const double* surface = ofMaterial ? materialColor : color;
      appearances.insert(appearances.end(), { color[0], color[1], color[2], display->GetSegmentOpacity3D(id), cuttable ? 0.0 : 1.0,
                                              cuttable ? node->GetSurfaceIsoValue() : 0.0, surface[0], surface[1], surface[2] });
    }
    if (appearances != pipeline.Appearances)
    {
      caster->RemoveAllSegmentAppearances();
      for (size_t index = 0; index < shown.size(); ++index)
      {
        const double* appearance = appearances.data() + AppearanceSize * index;
        const int label = static_cast<int>(index + 1);
        // NaN: drawn by its shape (a segment that is not cut shows its own surface).
        caster->SetSegmentAppearance(
          label, appearance, appearance[3], appearance[4] != 0.0 ? std::numeric_limits<double>::quiet_NaN() : appearance[5]);
        if (!std::equal(appearance, appearance + 3, appearance + 6))
        {
          caster->SetSegmentSurfaceColor(label, appearance + 6);
        }
      }
      pipeline.Appearances.swap(appearances);
    }
    pipeline.FractionSource = pipeline.LabelSource;
  }
  pipeline.Volume->SetVisibility(true);
}
