/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkSlicerVolumeCuttingSoftCutLogic_h
#define vtkSlicerVolumeCuttingSoftCutLogic_h

// MRML includes
#include <vtkMRMLAbstractLogic.h>

// VTK includes
#include <vtkSmartPointer.h>

// STD includes
#include <map>
#include <string>

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

class vtkMRMLMarkupsNode;
class vtkMRMLModelNode;
class vtkMRMLTableNode;
class vtkMRMLVolumeCutNode;
class vtkSlicerVolumeCuttingLogic;
class vtkVolumeCutResectionEstimate;
class vtkVolumeCutResectionPlanner;

/// \brief SoftCut: plan, preview, carve, measure and export a soft-tissue resection.
///
/// Blache et al.'s soft-tissue resection planning (vtkVolumeCutResectionPlanner)
/// on a volume-cut node: the outline is a markups closed curve whose points
/// lie on the skin of the node's anatomy (in desktop Slicer placed by picking
/// in the 3D view, and like any curve drawn in several sittings: the plan is
/// made when PlanResection is called); the depth of cut is previewed in 3D
/// views as a second removed region of the node (its preview field) without
/// recomputing the plan; the carve goes into the node's cut field through the
/// module logic, as one undo step with the cut node's shield applied, so
/// undo, the removed-volume table, the exports and the exact rendering work
/// as for drilling. The measurements of the resected tissue (volume, area,
/// extents in a local frame) go into a table node referenced by the cut node,
/// and its mesh into a model node or an STL file.
///
/// Every method returns false (or nullptr) for bad input, with the reason in
/// GetErrorMessage and the log, and changes nothing already planned or cut.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingSoftCutLogic : public vtkMRMLAbstractLogic
{
public:
  static vtkSlicerVolumeCuttingSoftCutLogic* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingSoftCutLogic, vtkMRMLAbstractLogic);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The module logic whose cut fields, strokes and tables the carve goes
  /// through. Default is none: set it before carving.
  void SetVolumeCuttingLogic(vtkSlicerVolumeCuttingLogic* logic);
  vtkSlicerVolumeCuttingLogic* GetVolumeCuttingLogic();
  ///@}

  ///@{
  /// Parameters of the next PlanResection (see vtkVolumeCutResectionPlanner):
  /// normal mode (vtkVolumeCutResectionPlanner::LocalNormal, default, or
  /// AverageNormal), skin iso-value (HU, default -500), soft-tissue range
  /// (HU, default -500 to 250), strip offset (mm, default 0: automatic),
  /// maximum depth of cut (mm, default 30), skin tolerance (mm, default 3).
  vtkSetMacro(NormalMode, int);
  vtkGetMacro(NormalMode, int);
  vtkSetMacro(SkinIsoValue, double);
  vtkGetMacro(SkinIsoValue, double);
  vtkSetVector2Macro(SoftTissueRange, double);
  vtkGetVector2Macro(SoftTissueRange, double);
  vtkSetMacro(StripOffset, double);
  vtkGetMacro(StripOffset, double);
  vtkSetMacro(MaximumDepth, double);
  vtkGetMacro(MaximumDepth, double);
  vtkSetMacro(SkinTolerance, double);
  vtkGetMacro(SkinTolerance, double);
  ///@}

  /// Plan the resection the outline (a vtkMRMLMarkupsClosedCurveNode with at
  /// least three control points on the skin of the cut node's anatomy)
  /// encloses. Replaces the node's previous plan and clears its preview.
  bool PlanResection(vtkMRMLVolumeCutNode* cutNode, vtkMRMLMarkupsNode* outline);

  /// The plan of a cut node (nullptr before PlanResection succeeded).
  vtkVolumeCutResectionPlanner* GetPlanner(vtkMRMLVolumeCutNode* cutNode);

  /// Show the resection at a depth of cut (mm) in 3D views, as the node's
  /// preview field (what the carve would leave, the node's shield included);
  /// the plan is reused, so the depth may change at every frame.
  bool PreviewDepth(vtkMRMLVolumeCutNode* cutNode, double depth);
  /// Remove the preview from the views.
  void ClearPreview(vtkMRMLVolumeCutNode* cutNode);

  /// Carve the planned resection at a depth of cut (mm) into the node's cut
  /// field: one undo step (vtkSlicerVolumeCuttingLogic::UndoStroke); clears the preview.
  bool CarveResection(vtkMRMLVolumeCutNode* cutNode, double depth);

  /// Measure the resected tissue at a depth of cut (mm) into the node's
  /// resection table (created on first use, referenced by the node): rows of
  /// Measurement, Value and Unit.
  vtkMRMLTableNode* MeasureResection(vtkMRMLVolumeCutNode* cutNode, double depth);
  static const char* GetResectionTableReferenceRole() { return "softCutResectionTable"; }

  /// The last measurement's estimate (mesh, volume, area, frame, extents).
  vtkVolumeCutResectionEstimate* GetEstimate(vtkMRMLVolumeCutNode* cutNode);

  /// A model node of the resected tissue at a depth of cut (closed, smoothed
  /// mesh in RAS), for display and for printing a harvesting guide.
  vtkMRMLModelNode* CreateResectionModel(vtkMRMLVolumeCutNode* cutNode, double depth, const char* name = nullptr);

  /// Write the resected tissue's mesh at a depth of cut to an STL file
  /// (Slicer's model storage, LPS coordinates as Slicer writes models).
  bool ExportResectionToSTL(vtkMRMLVolumeCutNode* cutNode, double depth, const char* fileName);

  /// What went wrong in the last call that failed ("" after a success).
  const char* GetErrorMessage() const { return this->ErrorMessage.c_str(); }

protected:
  vtkSlicerVolumeCuttingSoftCutLogic();
  ~vtkSlicerVolumeCuttingSoftCutLogic() override;
  vtkSlicerVolumeCuttingSoftCutLogic(const vtkSlicerVolumeCuttingSoftCutLogic&) = delete;
  void operator=(const vtkSlicerVolumeCuttingSoftCutLogic&) = delete;

  void SetMRMLSceneInternal(vtkMRMLScene* newScene) override;
  void OnMRMLSceneNodeRemoved(vtkMRMLNode* node) override;
  void OnMRMLSceneEndClose() override;

  bool Fail(const std::string& message);
  /// The plan of a node, with a message when there is none.
  vtkVolumeCutResectionPlanner* GetPlanOrFail(vtkMRMLVolumeCutNode* cutNode, const char* caller);
  /// The estimate at a depth (updated when the depth or the plan changed).
  vtkVolumeCutResectionEstimate* UpdateEstimate(vtkMRMLVolumeCutNode* cutNode, double depth, const char* caller);

  vtkSmartPointer<vtkSlicerVolumeCuttingLogic> VolumeCuttingLogic;
  int NormalMode = 0;
  double SkinIsoValue = -500.0;
  double SoftTissueRange[2] = { -500.0, 250.0 };
  double StripOffset = 0.0;
  double MaximumDepth = 30.0;
  double SkinTolerance = 3.0;
  std::string ErrorMessage;

  /// Plans and estimates by cut-node ID.
  std::map<std::string, vtkSmartPointer<vtkVolumeCutResectionPlanner>> Planners;
  std::map<std::string, vtkSmartPointer<vtkVolumeCutResectionEstimate>> Estimates;
};

#endif
