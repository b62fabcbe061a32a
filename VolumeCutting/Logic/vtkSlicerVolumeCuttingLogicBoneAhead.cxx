/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// The bone left ahead of the active tool, for the drill sound (seed 003).
// Part of vtkSlicerVolumeCuttingLogic.

#include "vtkSlicerVolumeCuttingLogic.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkSlicerVolumeCuttingSegmentImages.h"
#include "vtkVolumeCutBoneAhead.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutTool.h"

// MRML includes
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkMRMLTransformNode.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

// STD includes
#include <limits>

//----------------------------------------------------------------------------
vtkVolumeCutBoneAhead* vtkSlicerVolumeCuttingLogic::GetBoneAhead(vtkMRMLVolumeCutNode* cutNode)
{
  vtkMRMLScalarVolumeNode* anatomy = cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr;
  vtkMRMLSegmentationNode* segmentation = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  if (!cutNode || !cutNode->GetID() || !anatomy || !anatomy->GetImageData() || !segmentation)
  {
    return nullptr;
  }
  BoneAheadQuery& state = this->BoneAheadQueries[cutNode->GetID()];
  const std::vector<std::string> bone = cutNode->GetCuttableSegmentIDs();
  const std::string source = vtkSlicerVolumeCuttingSegmentImages::DescribeLabelSource(anatomy, segmentation, bone);
  if (source != state.Source)
  {
    // The bone changed (other cuttable segments, their voxels, the grid): a new mask.
    state.Source = source;
    state.Query = nullptr;
    vtkNew<vtkImageData> labels;
    const std::vector<std::string> missing = bone.empty() ? bone : vtkSlicerVolumeCuttingSegmentImages::CreateLabelMap(anatomy, segmentation, bone, labels);
    vtkNew<vtkMatrix4x4> ijkToRAS;
    anatomy->GetIJKToRASMatrix(ijkToRAS);
    vtkNew<vtkVolumeCutBoneAhead> query;
    // No cuttable segment, or none with a voxel: no bone to thin (SetBone would name the latter as an error).
    bool hasBone = false;
    if (!bone.empty() && missing.size() < bone.size())
    {
      double range[2] = { 0.0, 0.0 };
      labels->GetScalarRange(range);
      hasBone = range[1] > 0.0 && query->SetBone(labels, ijkToRAS);
    }
    if (hasBone)
    {
      state.Query = query;
    }
  }
  if (state.Query)
  {
    // The field the logic cuts; none before the first cut: the bone as segmented.
    vtkVolumeCutField* field = cutNode->GetCutField();
    state.Query->SetCutField(field && field->GetSubVoxelFactor() > 0 ? field : nullptr);
  }
  return state.Query;
}

//----------------------------------------------------------------------------
double vtkSlicerVolumeCuttingLogic::MeasureBoneAhead(vtkMRMLVolumeCutNode* cutNode)
{
  vtkMRMLVolumeCutToolNode* toolNode = GetActiveTool(cutNode);
  vtkNew<vtkMatrix4x4> toolToRAS;
  if (toolNode && toolNode->GetParentTransformNode())
  {
    toolNode->GetParentTransformNode()->GetMatrixTransformToWorld(toolToRAS);
  }
  return this->MeasureBoneAhead(cutNode, toolToRAS);
}

//----------------------------------------------------------------------------
double vtkSlicerVolumeCuttingLogic::MeasureBoneAhead(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* toolToRAS)
{
  const double nothing = std::numeric_limits<double>::infinity();
  vtkMRMLVolumeCutToolNode* toolNode = GetActiveTool(cutNode);
  vtkVolumeCutBoneAhead* query = toolNode && toolToRAS ? this->GetBoneAhead(cutNode) : nullptr;
  if (!query)
  {
    return nothing;
  }
  // From the tip of the cutting part, away from the handpiece (the shaft is local +z): the round burr's
  // radius (swept as a capsule, it has no tool object), or the extent along the shaft of the other shapes.
  double reach = toolNode->GetCuttingRadius();
  if (vtkVolumeCutTool* tool = this->GetCuttingTool(toolNode))
  {
    double halfExtents[3];
    tool->GetLocalHalfExtents(halfExtents);
    reach = halfExtents[2];
  }
  const double tipLocal[4] = { 0.0, 0.0, -reach, 1.0 };
  double tip[4];
  toolToRAS->MultiplyPoint(tipLocal, tip);
  const double ahead[3] = { -toolToRAS->GetElement(0, 2), -toolToRAS->GetElement(1, 2), -toolToRAS->GetElement(2, 2) };
  return query->Measure(tip, ahead);
}
