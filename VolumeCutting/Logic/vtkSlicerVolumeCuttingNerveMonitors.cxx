/*==============================================================================
  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.
  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0
==============================================================================*/

#include "vtkSlicerVolumeCuttingNerveMonitors.h"
#include "vtkSlicerVolumeCuttingSegmentImages.h"
#include "vtkSlicerVolumeCuttingTables.h"

// MRML includes
#include "vtkMRMLVolumeCutNode.h"
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>
#include <vtkMRMLTableNode.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>

// STD includes
#include <chrono>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>

vtkStandardNewMacro(vtkSlicerVolumeCuttingNerveMonitors);

struct vtkSlicerVolumeCuttingNerveMonitors::State
{
  vtkNew<vtkVolumeCutNerveMonitor> Monitor;
  std::vector<std::string> Chosen;
  std::vector<std::string> SegmentIds; // monitored now, by structure index
  std::vector<std::string> Names;
  std::string Source;                  // what the monitor was built from
  std::chrono::steady_clock::time_point Start = std::chrono::steady_clock::now();
  std::vector<double> LastRowTimes;
  int LevelChanges = 0;

  // One builder per monitor, asked again whenever the structures change. A
  // role change must not wait for the fields of the previous choice (seconds
  // on a large scan): the monitor drops a field whose structures changed
  // while it was built, and the builder then builds the new ones.
  std::thread Builder;
  std::mutex BuilderMutex;
  std::condition_variable BuilderChanged;
  bool BuildRequested = false;
  bool Building = false;
  bool Stopping = false;

  void RequestBuild()
  {
    std::lock_guard<std::mutex> lock(this->BuilderMutex);
    this->BuildRequested = true;
    if (!this->Builder.joinable())
    {
      this->Builder = std::thread([this] { this->BuildWhenAsked(); });
    }
    this->BuilderChanged.notify_all();
  }

  void BuildWhenAsked()
  {
    std::unique_lock<std::mutex> lock(this->BuilderMutex);
    for (;;)
    {
      this->BuilderChanged.wait(lock, [this] { return this->BuildRequested || this->Stopping; });
      if (this->Stopping)
      {
        return;
      }
      this->BuildRequested = false;
      this->Building = true;
      lock.unlock();
      this->Monitor->Build();
      lock.lock();
      this->Building = false;
      this->BuilderChanged.notify_all();
    }
  }

  void WaitUntilIdle()
  {
    std::unique_lock<std::mutex> lock(this->BuilderMutex);
    this->BuilderChanged.wait(lock, [this] { return !this->BuildRequested && !this->Building; });
  }

  ~State()
  {
    {
      std::lock_guard<std::mutex> lock(this->BuilderMutex);
      this->Stopping = true;
      this->BuilderChanged.notify_all();
    }
    if (this->Builder.joinable())
    {
      this->Builder.join();
    }
  }
};

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingNerveMonitors::vtkSlicerVolumeCuttingNerveMonitors() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingNerveMonitors::~vtkSlicerVolumeCuttingNerveMonitors() = default;

//----------------------------------------------------------------------------
vtkSlicerVolumeCuttingNerveMonitors::State* vtkSlicerVolumeCuttingNerveMonitors::GetState(vtkMRMLVolumeCutNode* cutNode)
{
  if (!cutNode || !cutNode->GetID())
  {
    return nullptr;
  }
  std::unique_ptr<State>& state = this->States[cutNode->GetID()];
  if (!state)
  {
    state.reset(new State);
  }
  return state.get();
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingNerveMonitors::SetChosenSegmentIDs(vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds)
{
  State* state = this->GetState(cutNode);
  if (state)
  {
    state->Chosen = segmentIds;
  }
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkSlicerVolumeCuttingNerveMonitors::GetMonitoredSegmentIDs(vtkMRMLVolumeCutNode* cutNode)
{
  State* state = this->GetState(cutNode);
  if (!state)
  {
    return {};
  }
  return state->Chosen.empty() ? cutNode->GetProtectedSegmentIDs() : state->Chosen;
}

//----------------------------------------------------------------------------
vtkVolumeCutNerveMonitor* vtkSlicerVolumeCuttingNerveMonitors::GetMonitor(vtkMRMLVolumeCutNode* cutNode)
{
  State* state = this->GetState(cutNode);
  vtkMRMLScalarVolumeNode* anatomy = cutNode ? cutNode->GetAnatomyVolumeNode() : nullptr;
  vtkMRMLSegmentationNode* segmentation = cutNode ? cutNode->GetSegmentationNode() : nullptr;
  if (!state || !anatomy || !anatomy->GetImageData() || !segmentation)
  {
    return nullptr;
  }
  const std::vector<std::string> wanted = this->GetMonitoredSegmentIDs(cutNode);
  if (wanted.empty())
  {
    return nullptr;
  }
  std::ostringstream source;
  source << vtkSlicerVolumeCuttingSegmentImages::DescribeLabelSource(anatomy, segmentation, wanted);
  source << ";" << cutNode->GetLabelSmoothing();
  if (source.str() == state->Source)
  {
    return state->SegmentIds.empty() ? nullptr : state->Monitor.GetPointer();
  }
  // The segments changed: new structures from their labels on the anatomy's grid.
  state->Source = source.str();
  state->SegmentIds.clear();
  state->Names.clear();
  vtkNew<vtkImageData> labels;
  vtkSlicerVolumeCuttingSegmentImages::CreateLabelMap(anatomy, segmentation, wanted, labels);
  vtkNew<vtkMatrix4x4> ijkToRAS;
  anatomy->GetIJKToRASMatrix(ijkToRAS);
  vtkVolumeCutNerveMonitor* monitor = state->Monitor;
  // The shield's smoothing, 0 included (the voxel cubes): the monitor reads contact where the cut stops.
  monitor->SetSmoothing(cutNode->GetLabelSmoothing());
  if (!monitor->SetGeometry(anatomy->GetImageData()->GetDimensions(), ijkToRAS))
  {
    vtkErrorMacro("GetMonitor: the scan '" << (anatomy->GetName() ? anatomy->GetName() : "") << "' cannot be monitored (see the error above)");
    return nullptr;
  }
  for (size_t n = 0; n < wanted.size(); ++n)
  {
    vtkSegment* segment = segmentation->GetSegmentation()->GetSegment(wanted[n]);
    const std::string name = segment && segment->GetName() ? segment->GetName() : wanted[n];
    // Refused structures (empty, outside the scan) are named in the log and left out.
    if (monitor->AddStructure(name.c_str(), labels, static_cast<int>(n + 1)) >= 0)
    {
      state->SegmentIds.push_back(wanted[n]);
      state->Names.push_back(name);
    }
  }
  state->LastRowTimes.assign(state->SegmentIds.size(), -std::numeric_limits<double>::infinity());
  state->Start = std::chrono::steady_clock::now();
  if (state->SegmentIds.empty())
  {
    return nullptr;
  }
  // The fields are built off the threads that measure: readings are "not ready" until then.
  state->RequestBuild();
  return monitor;
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingNerveMonitors::Wait(vtkMRMLVolumeCutNode* cutNode)
{
  State* state = this->GetState(cutNode);
  if (!state || !this->GetMonitor(cutNode))
  {
    return false;
  }
  state->WaitUntilIdle();
  return state->Monitor->IsBuilt();
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingNerveMonitors::UpdateWithTool(
  vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, double radius, vtkMatrix4x4* toolToRAS)
{
  vtkVolumeCutNerveMonitor* monitor = this->GetMonitor(cutNode);
  if (!monitor || !toolToRAS)
  {
    return false;
  }
  if (tool)
  {
    monitor->UpdateWithTool(tool, toolToRAS);
  }
  else
  {
    const double centre[3] = { toolToRAS->GetElement(0, 3), toolToRAS->GetElement(1, 3), toolToRAS->GetElement(2, 3) };
    monitor->UpdateWithBurr(centre, radius);
  }
  return this->Record(scene, cutNode, *this->GetState(cutNode));
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingNerveMonitors::UpdateWithReadings(
  vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const vtkVolumeCutNerveMonitor::Reading* readings, int count)
{
  vtkVolumeCutNerveMonitor* monitor = this->GetMonitor(cutNode);
  if (!monitor || !readings || count < 0)
  {
    return false;
  }
  monitor->UpdateWithReadings(readings, count);
  return this->Record(scene, cutNode, *this->GetState(cutNode));
}

//----------------------------------------------------------------------------
bool vtkSlicerVolumeCuttingNerveMonitors::Record(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, State& state)
{
  vtkVolumeCutNerveMonitor* monitor = state.Monitor;
  const bool levelChanged = monitor->GetNumberOfLevelChanges() != state.LevelChanges;
  state.LevelChanges = monitor->GetNumberOfLevelChanges();
  if (!scene)
  {
    return levelChanged;
  }
  const double now = std::chrono::duration<double>(std::chrono::steady_clock::now() - state.Start).count();
  vtkMRMLTableNode* table = nullptr;
  int wasModifying = 0;
  for (size_t index = 0; index < state.SegmentIds.size(); ++index)
  {
    const int level = monitor->GetLevel(static_cast<int>(index));
    if (level == vtkVolumeCutNerveMonitor::NotReady || (now - state.LastRowTimes[index] < this->TableInterval && !levelChanged))
    {
      continue;
    }
    if (!table)
    {
      table = vtkSlicerVolumeCuttingTables::GetNerveMonitorTable(scene, cutNode, GetTableReferenceRole());
      if (!table)
      {
        return levelChanged;
      }
      wasModifying = table->StartModify();
    }
    vtkSlicerVolumeCuttingTables::AddNerveReading(table, now, state.SegmentIds[index], state.Names[index],
      monitor->GetDistance(static_cast<int>(index)), vtkVolumeCutNerveMonitor::GetLevelAsString(level));
    state.LastRowTimes[index] = now;
  }
  if (table)
  {
    table->EndModify(wasModifying);
  }
  return levelChanged;
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingNerveMonitors::Forget(const std::string& nodeId)
{
  this->States.erase(nodeId);
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingNerveMonitors::ForgetAll()
{
  this->States.clear();
}

//----------------------------------------------------------------------------
void vtkSlicerVolumeCuttingNerveMonitors::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TableInterval: " << this->TableInterval << " s\n";
  os << indent << "Monitored cut nodes: " << this->States.size() << "\n";
  for (const auto& entry : this->States)
  {
    os << indent.GetNextIndent() << entry.first << ": " << entry.second->SegmentIds.size() << " segments\n";
  }
}
