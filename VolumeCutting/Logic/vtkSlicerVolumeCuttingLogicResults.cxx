/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// What a cut removed: removed voxels and volumes (per segment too), the
// tables the user follows while drilling, and exports to Slicer nodes.
// Part of vtkSlicerVolumeCuttingLogic.

#include "vtkSlicerVolumeCuttingLogic.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkSlicerVolumeCuttingExporter.h"
#include "vtkSlicerVolumeCuttingSegmentLayers.h"
#include "vtkSlicerVolumeCuttingTables.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutRemovedVoxels.h"

// MRML includes
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkMRMLTableNode.h>

// SegmentationCore includes
#include <vtkSegmentation.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

// STD includes
#include <cmath>

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::UpdateTablesAfterChange(vtkMRMLVolumeCutNode* cutNode)
{
  // Only a table the user asked for is kept up to date: its cost follows the cut.
  if (cutNode && cutNode->GetNodeReference(GetRemovedVolumeTableReferenceRole()))
  {
    this->UpdateRemovedVolumeTable(cutNode);
  }
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingLogic::RecordContact(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field)
{
  const double depth = field->GetMaximumContactDepth();
  if (!(depth > 0.0) || !cutNode->GetID())
  {
    return;
  }
  vtkMRMLTableNode* table = this->GetContactTableNode(cutNode);
  if (!table)
  {
    return;
  }
  vtkSlicerVolumeCuttingTables::AddContact(table, cutNode, this->GetContactSegmentID(cutNode), depth, field->GetContactPosition());
}

//----------------------------------------------------------------------------
double vtkSlicerVolumeCuttingLogic::GetRemovedVolume(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  if (!voxels)
  {
    return 0.0;
  }
  vtkNew<vtkMatrix4x4> ijkToRas;
  cutNode->GetAnatomyVolumeNode()->GetIJKToRASMatrix(ijkToRas);
  return voxels->GetTotalFraction() * std::abs(ijkToRas->Determinant());
}

//----------------------------------------------------------------------------
vtkVolumeCutRemovedVoxels* vtkSlicerVolumeCuttingLogic::UpdateRemovedVoxels(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field)
  {
    return nullptr;
  }
  vtkSmartPointer<vtkVolumeCutRemovedVoxels>& voxels = this->RemovedVoxels[cutNode->GetID()];
  if (!voxels)
  {
    voxels = vtkSmartPointer<vtkVolumeCutRemovedVoxels>::New();
  }
  voxels->Update(field);
  return voxels;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingLogic::GetRemovedVoxels(vtkMRMLVolumeCutNode* cutNode, vtkIdTypeArray* voxelIds, vtkFloatArray* fractions)
{
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  if (!voxels)
  {
    return false;
  }
  voxels->GetVoxels(voxelIds, fractions);
  return true;
}

//----------------------------------------------------------------------------
std::map<std::string, double> vtkSlicerVolumeCuttingLogic::ComputeRemovedVolumePerSegment(
  vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds)
{
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  vtkSlicerVolumeCuttingSegmentLayers* layers = voxels ? this->GetSegmentLayers(cutNode) : nullptr;
  if (!layers)
  {
    return {};
  }
  vtkMRMLScalarVolumeNode* anatomy = cutNode->GetAnatomyVolumeNode();
  std::map<std::string, double> volumes = layers->SumRemovedFractions(voxels, anatomy->GetImageData()->GetDimensions(), segmentIds);
  vtkNew<vtkMatrix4x4> ijkToRas;
  anatomy->GetIJKToRASMatrix(ijkToRas);
  const double voxelVolume = std::abs(ijkToRas->Determinant());
  for (auto& entry : volumes)
  {
    entry.second *= voxelVolume;
  }
  return volumes;
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
  if (!this->GetCutField(cutNode))
  {
    return -1.0;
  }
  const std::map<std::string, double> volumes = this->ComputeRemovedVolumePerSegment(cutNode, { segmentId });
  auto found = volumes.find(segmentId);
  if (found == volumes.end())
  {
    vtkErrorMacro("GetRemovedVolumeInSegment: segment '" << segmentId << "' has no binary labelmap");
    return -1.0;
  }
  return found->second;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::GetRemovedVolumeTableNode(vtkMRMLVolumeCutNode* cutNode)
{
  if (!cutNode || !this->GetMRMLScene())
  {
    vtkErrorMacro("GetRemovedVolumeTableNode: no volume-cut node in a scene");
    return nullptr;
  }
  bool created = false;
  vtkMRMLTableNode* table = vtkSlicerVolumeCuttingTables::GetRemovedVolumeTable(this->GetMRMLScene(), cutNode, GetRemovedVolumeTableReferenceRole(), created);
  if (created)
  {
    this->UpdateRemovedVolumeTable(cutNode);
  }
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::GetContactTableNode(vtkMRMLVolumeCutNode* cutNode)
{
  if (!cutNode || !this->GetMRMLScene())
  {
    vtkErrorMacro("GetContactTableNode: no volume-cut node in a scene");
    return nullptr;
  }
  return vtkSlicerVolumeCuttingTables::GetContactTable(this->GetMRMLScene(), cutNode, GetContactTableReferenceRole());
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingLogic::UpdateRemovedVolumeTable(vtkMRMLVolumeCutNode* cutNode)
{
  vtkMRMLTableNode* table = vtkMRMLTableNode::SafeDownCast(cutNode ? cutNode->GetNodeReference(GetRemovedVolumeTableReferenceRole()) : nullptr);
  if (!table)
  {
    return this->GetRemovedVolumeTableNode(cutNode);
  }
  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  std::vector<std::string> segmentIds;
  if (segmentationNode)
  {
    segmentationNode->GetSegmentation()->GetSegmentIDs(segmentIds);
  }
  vtkSlicerVolumeCuttingTables::FillRemovedVolumeTable(table, cutNode, segmentIds, this->ComputeRemovedVolumePerSegment(cutNode, segmentIds));
  return table;
}

//----------------------------------------------------------------------------
vtkImageData* vtkSlicerVolumeCuttingLogic::GetRemovedFraction(vtkMRMLVolumeCutNode* cutNode)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field)
  {
    return nullptr;
  }
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  auto& cached = this->RemovedFractions[cutNode->GetID()];
  if (!cached.second || cached.first != voxels->GetMTime())
  {
    // Dense, from the tally of removed voxels: only the cut's voxels are written.
    cached.second = vtkSmartPointer<vtkImageData>::New();
    voxels->ExportFraction(cutNode->GetAnatomyVolumeNode()->GetImageData()->GetDimensions(), cached.second);
    cached.first = voxels->GetMTime();
  }
  return cached.second;
}

//----------------------------------------------------------------------------
vtkMRMLSegmentationNode* vtkSlicerVolumeCuttingLogic::ExportRemovedRegionToSegmentation(vtkMRMLVolumeCutNode* cutNode, const char* name)
{
  vtkImageData* fraction = this->GetRemovedFraction(cutNode);
  if (!fraction || !this->GetMRMLScene())
  {
    return nullptr;
  }
  return vtkSlicerVolumeCuttingExporter::AddRemovedRegionSegmentation(this->GetMRMLScene(), cutNode, fraction, name);
}

//----------------------------------------------------------------------------
vtkMRMLModelNode* vtkSlicerVolumeCuttingLogic::ExportRemovedSurfaceToModel(vtkMRMLVolumeCutNode* cutNode, const char* name)
{
  vtkVolumeCutField* field = this->GetCutField(cutNode);
  if (!field || !this->GetMRMLScene())
  {
    return nullptr;
  }
  return vtkSlicerVolumeCuttingExporter::AddRemovedSurfaceModel(this->GetMRMLScene(), cutNode, field, name);
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingLogic::ExportRemovedFractionToVolume(vtkMRMLVolumeCutNode* cutNode, const char* name)
{
  vtkImageData* fraction = this->GetRemovedFraction(cutNode);
  if (!fraction || !this->GetMRMLScene())
  {
    return nullptr;
  }
  return vtkSlicerVolumeCuttingExporter::AddRemovedFractionVolume(this->GetMRMLScene(), cutNode, fraction, name);
}

//----------------------------------------------------------------------------
vtkMRMLScalarVolumeNode* vtkSlicerVolumeCuttingLogic::ExportDrilledVolume(vtkMRMLVolumeCutNode* cutNode, double fillValue, const char* name)
{
  vtkVolumeCutRemovedVoxels* voxels = this->UpdateRemovedVoxels(cutNode);
  if (!voxels || !this->GetMRMLScene())
  {
    return nullptr;
  }
  return vtkSlicerVolumeCuttingExporter::AddDrilledVolume(this->GetMRMLScene(), cutNode, voxels, fillValue, name);
}
