/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkSlicerVolumeCuttingTables.h"

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"

// MRML includes
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkMRMLTableNode.h>

// SegmentationCore includes
#include <vtkSegment.h>
#include <vtkSegmentation.h>

// VTK includes
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkStringArray.h>
#include <vtkTable.h>

// STD includes
#include <algorithm>
#include <chrono>
#include <ctime>
#include <iomanip>
#include <sstream>

vtkStandardNewMacro(vtkSlicerVolumeCuttingTables);

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingTables::vtkSlicerVolumeCuttingTables() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingTables::~vtkSlicerVolumeCuttingTables() = default;

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingTables::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingTables::GetReferencedTable(
  vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role, const char* nameSuffix, const std::vector<std::string>& columns)
{
  vtkMRMLTableNode* table = vtkMRMLTableNode::SafeDownCast(cutNode->GetNodeReference(role));
  if (table)
  {
    return table;
  }
  const std::string name = scene->GenerateUniqueName(std::string(cutNode->GetName() ? cutNode->GetName() : "Cut") + " " + nameSuffix);
  table = vtkMRMLTableNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLTableNode", name));
  if (!table)
  {
    return nullptr;
  }
  for (const std::string& column : columns)
  {
    vtkNew<vtkStringArray> array;
    array->SetName(column.c_str());
    table->AddColumn(array);
  }
  cutNode->SetNodeReferenceID(role, table->GetID());
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingTables::GetRemovedVolumeTable(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role, bool& created)
{
  const bool existed = cutNode->GetNodeReference(role) != nullptr;
  vtkMRMLTableNode* table = GetReferencedTable(scene, cutNode, role, "removed volume", { "Segment", "Name", "Role", "Removed volume" });
  created = table && !existed;
  if (created)
  {
    table->SetColumnUnitLabel("Removed volume", "mm3");
    table->SetColumnDescription("Removed volume", "Volume removed inside the segment by the cut");
  }
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingTables::GetContactTable(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role)
{
  const bool existed = cutNode->GetNodeReference(role) != nullptr;
  vtkMRMLTableNode* table = GetReferencedTable(scene, cutNode, role, "contacts", { "Segment", "Name", "Time", "Depth", "R", "A", "S" });
  if (table && !existed)
  {
    table->SetColumnUnitLabel("Depth", "mm");
    table->SetColumnDescription("Depth", "Deepest penetration of the tool into a segment it may not cut, in one stroke");
    table->SetColumnDescription("Time", "End of the stroke (UTC)");
  }
  return table;
}

//----------------------------------------------------------------------------
vtkMRMLTableNode* vtkSlicerVolumeCuttingTables::GetNerveMonitorTable(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role)
{
  const bool existed = cutNode->GetNodeReference(role) != nullptr;
  vtkMRMLTableNode* table = GetReferencedTable(scene, cutNode, role, "nerve monitor", { "Time", "Segment", "Name", "Distance", "Level" });
  if (table && !existed)
  {
    table->SetColumnUnitLabel("Time", "s");
    table->SetColumnDescription("Time", "Since the monitor started");
    table->SetColumnUnitLabel("Distance", "mm");
    table->SetColumnDescription("Distance", "From the tool's surface to the segment's smoothed surface (negative: inside)");
    table->SetColumnDescription("Level", "silent, sparse clicks, bursts, continuous or contact");
  }
  return table;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingTables::AddNerveReading(
  vtkMRMLTableNode* table, double time, const std::string& segmentId, const std::string& name, double distance, const char* level)
{
  const int row = table->AddEmptyRow();
  std::ostringstream value;
  value << time;
  table->SetCellText(row, 0, value.str().c_str());
  table->SetCellText(row, 1, segmentId.c_str());
  table->SetCellText(row, 2, name.c_str());
  value.str("");
  value << distance;
  table->SetCellText(row, 3, value.str().c_str());
  table->SetCellText(row, 4, level);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingTables::FillRemovedVolumeTable(
  vtkMRMLTableNode* table, vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds, const std::map<std::string, double>& volumes)
{
  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  const int wasModifying = table->StartModify();
  table->GetTable()->SetNumberOfRows(0);
  for (const std::string& segmentId : segmentIds)
  {
    auto found = volumes.find(segmentId);
    const double removed = found != volumes.end() ? found->second : 0.0;
    vtkSegment* segment = segmentationNode->GetSegmentation()->GetSegment(segmentId);
    const int row = table->AddEmptyRow();
    table->SetCellText(row, 0, segmentId.c_str());
    table->SetCellText(row, 1, segment && segment->GetName() ? segment->GetName() : "");
    table->SetCellText(row, 2, cutNode->IsSegmentCuttable(segmentId) ? "cuttable" : cutNode->IsSegmentProtected(segmentId) ? "protected" : "none");
    std::ostringstream text;
    text << std::fixed << std::setprecision(3) << std::max(0.0, removed);
    table->SetCellText(row, 3, text.str().c_str());
  }
  table->EndModify(wasModifying);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingTables::AddContact(
  vtkMRMLTableNode* table, vtkMRMLVolumeCutNode* cutNode, const std::string& segmentId, double depth, const double position[3])
{
  vtkMRMLSegmentationNode* segmentationNode = cutNode->GetSegmentationNode();
  vtkSegment* segment = segmentationNode && !segmentId.empty() ? segmentationNode->GetSegmentation()->GetSegment(segmentId) : nullptr;
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
#ifdef _WIN32
  gmtime_s(&utc, &now);
#else
  gmtime_r(&now, &utc);
#endif
  std::ostringstream time;
  time << std::put_time(&utc, "%Y-%m-%dT%H:%M:%SZ");
  const int row = table->AddEmptyRow();
  table->SetCellText(row, 0, segmentId.c_str());
  table->SetCellText(row, 1, segment && segment->GetName() ? segment->GetName() : "");
  table->SetCellText(row, 2, time.str().c_str());
  std::ostringstream value;
  for (int column = 3; column < 7; ++column)
  {
    value.str("");
    value << (column == 3 ? depth : position[column - 4]);
    table->SetCellText(row, column, value.str().c_str());
  }
}
