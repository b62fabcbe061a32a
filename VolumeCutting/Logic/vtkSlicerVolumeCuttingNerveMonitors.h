/*==============================================================================
  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.
  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0
==============================================================================*/
#ifndef vtkSlicerVolumeCuttingNerveMonitors_h
#define vtkSlicerVolumeCuttingNerveMonitors_h

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

// VTK includes
#include <vtkObject.h>
#include <vtkWrappingHints.h>

// VolumeCutting includes
#include "vtkVolumeCutNerveMonitor.h"

// STD includes
#include <map>
#include <memory>
#include <string>
#include <vector>

class vtkMRMLScene;
class vtkMRMLVolumeCutNode;
class vtkMatrix4x4;
class vtkVolumeCutTool;

/// \brief The nerve monitor (vtkVolumeCutNerveMonitor) of each cut node, for the module logic.
///
/// Which segments a node's monitor watches (by default its protected ones,
/// else the list the user chose), the monitor built from the segmentation's
/// labels on the anatomy's grid when that changes (its distance fields on a
/// worker thread: the mouse and the haptic tick never wait for them), and
/// the table of readings over time. The module logic forwards to it.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingNerveMonitors : public vtkObject
{
public:
  static vtkSlicerVolumeCuttingNerveMonitors* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingNerveMonitors, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The node's monitor, (re)configured when its segments, segmentation or
  /// anatomy changed; nullptr when no segment is monitored.
  vtkVolumeCutNerveMonitor* GetMonitor(vtkMRMLVolumeCutNode* cutNode);
  /// The segments to monitor (empty: the node's protected segments).
  void SetChosenSegmentIDs(vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds);
  std::vector<std::string> GetMonitoredSegmentIDs(vtkMRMLVolumeCutNode* cutNode);
  /// Wait for the node's fields to be built; false without a monitor.
  bool Wait(vtkMRMLVolumeCutNode* cutNode);

  /// New readings of the node's monitor: for a tool at a pose (tool nullptr:
  /// a spherical burr of radius at the pose's origin), or given (a haptic
  /// tick's). Rows go to the table (at most one per structure per
  /// TableInterval, and at every change of level). Returns whether a level changed.
  bool UpdateWithTool(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, double radius, vtkMatrix4x4* toolToRAS);
  VTK_WRAPEXCLUDE bool UpdateWithReadings(
    vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const vtkVolumeCutNerveMonitor::Reading* readings, int count);

  ///@{
  /// Set/get the least time (s) between two rows of one structure in the table. Default is 0.05.
  vtkSetClampMacro(TableInterval, double, 0.0, 3600.0);
  vtkGetMacro(TableInterval, double);
  ///@}

  /// Forget a node's monitor (its builder is waited for), or every node's.
  void Forget(const std::string& nodeId);
  void ForgetAll();

  static const char* GetTableReferenceRole() { return "nerveMonitorTable"; }

protected:
  vtkSlicerVolumeCuttingNerveMonitors();
  ~vtkSlicerVolumeCuttingNerveMonitors() override;

  struct State;
  std::map<std::string, std::unique_ptr<State>> States;
  State* GetState(vtkMRMLVolumeCutNode* cutNode);
  /// Append the current readings to the node's table; returns whether a level changed.
  bool Record(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, State& state);
  double TableInterval = 0.05;

private:
  vtkSlicerVolumeCuttingNerveMonitors(const vtkSlicerVolumeCuttingNerveMonitors&) = delete;
  void operator=(const vtkSlicerVolumeCuttingNerveMonitors&) = delete;
};

#endif
