/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkSlicerVolumeCuttingLogic_h
#define vtkSlicerVolumeCuttingLogic_h

// Slicer includes
#include <vtkSlicerModuleLogic.h>

// STD includes
#include <map>
#include <memory>
#include <string>
#include <vector>

// VTK includes
#include <vtkCommand.h>
#include <vtkSmartPointer.h>
#include <vtkWrappingHints.h>


#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

class vtkMRMLMessageCollection;
class vtkMRMLModelNode;
class vtkMRMLTableNode;
class vtkFloatArray;
class vtkIdTypeArray;
class vtkSlicerVolumeCuttingSegmentLayers;
class vtkSlicerVolumeCuttingNerveMonitors;
class vtkSlicerVolumeCuttingToolCache;
class vtkVolumeCutBoneAhead;
class vtkVolumeCutNerveMonitor;
class vtkMRMLScalarVolumeNode;
class vtkMRMLSegmentationNode;
class vtkMRMLVolumeCutNode;
class vtkImageData;
class vtkMatrix4x4;
class vtkVolumeCutField;
class vtkVolumeCutMaterialRemoval;
class vtkVolumeCutRemovedVoxels;
class vtkVolumeCutTool;
class vtkMRMLVolumeCutToolNode;

/// \brief Builds and checks volume-cutting sessions.
///
/// The logic is thin on purpose: algorithms live in the Slicer-independent
/// vtkVolumeCuttingCore library, and this class connects them to MRML nodes.
/// Any source of work (the module widget, a Python script, a replay) uses the
/// same methods, so they are tested without a GUI.
///
/// Its implementation is split by responsibility: node registration, scene
/// observation and input checks (vtkSlicerVolumeCuttingLogic.cxx); the cut
/// field of a node, its grid and its shield (...LogicCutField.cxx); strokes
/// and tool motion (...LogicStrokes.cxx); removed volume, tables and exports
/// (...LogicResults.cxx). Helpers that need no per-node state are classes of
/// their own: vtkSlicerVolumeCuttingToolCache, vtkSlicerVolumeCuttingSegmentImages,
/// vtkSlicerVolumeCuttingTables and vtkSlicerVolumeCuttingExporter.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingLogic : public vtkSlicerModuleLogic
{
public:
  static vtkSlicerVolumeCuttingLogic* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingLogic, vtkSlicerModuleLogic);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Segment IDs of the bone segmentation made by CreateBoneSegmentation.
  static const char* GetCorticalBoneSegmentID() { return "CorticalBone"; }
  static const char* GetTrabecularBoneSegmentID() { return "TrabecularBone"; }

  /// Segment the anatomy's bone into cortical and trabecular segments by
  /// region growing (vtkImageBoneSegmentation) and add the segmentation to the
  /// scene, on the anatomy's voxel grid. Thresholds are in the volume's units
  /// (Hounsfield units for CT); smoothing is a Gaussian standard deviation in
  /// millimetres, 0 for none.
  /// Returns nullptr and logs an error if the volume has no voxels or the
  /// thresholds are invalid; nothing is added to the scene then.
  vtkMRMLSegmentationNode* CreateBoneSegmentation(vtkMRMLScalarVolumeNode* anatomyVolume,
                                                  double corticalThreshold = 700.0,
                                                  double trabecularThreshold = 200.0,
                                                  double smoothingStandardDeviationMm = 0.0);

  /// Add a volume-cut node for this anatomy and segmentation (either may be
  /// nullptr and set later). The segmentation's reference geometry is set to
  /// the anatomy's grid if it has none.
  vtkMRMLVolumeCutNode* AddVolumeCutNode(vtkMRMLScalarVolumeNode* anatomyVolume, vtkMRMLSegmentationNode* segmentation);

  /// Check that a cut node's inputs can be cut: an anatomy volume with voxels
  /// and finite positive spacing; a segmentation on the same voxel grid; roles
  /// that name existing segments. Problems are added to \a messages (errors
  /// for what prevents cutting, warnings for what degrades it) and logged.
  /// Returns true when there is no error.
  bool CheckInputs(vtkMRMLVolumeCutNode* cutNode, vtkMRMLMessageCollection* messages);

  /// The cut field of a cut node (held by the node, saved with the scene),
  /// created on first use on the anatomy's voxel grid at the node's sub-voxel
  /// factor. Grids are compared to a thousandth of a voxel, so a field read
  /// back from a saved scene is kept bit for bit. When the anatomy's grid or
  /// the factor really changes, the cut is resampled onto the new grid (a
  /// warning says what changed; the undo history is cleared); if part of the
  /// cut would be lost (the new grid does not cover it), the change is refused
  /// with an error, the old cut stays and nullptr is returned until the grid
  /// is put back or the cut is cleared (ClearCut).
  /// Its shield follows the node's segments without a cuttable role (labels
  /// 1, 2, ... in the order of GetShieldedSegmentIDs), read from the
  /// segmentation's labelmap layers where tools reach.
  /// nullptr (and an error) when the node has no anatomy with voxels.
  vtkVolumeCutField* GetCutField(vtkMRMLVolumeCutNode* cutNode);

  /// Discard the node's cut (not undoable); the next use starts an empty field.
  void ClearCut(vtkMRMLVolumeCutNode* cutNode);

  /// Segments kept out of cutting, in label order (label n is element n - 1):
  /// those the active tool may not cut (by default: those without a
  /// cuttable role) first, then the protected ones, so that where segments
  /// overlap a protected one names the voxel.
  static std::vector<std::string> GetShieldedSegmentIDs(vtkMRMLVolumeCutNode* cutNode);

  ///@{
  /// Strokes from any source (mouse, haptic device, replay) go through here.
  /// A stroke of a spherical burr of the given radius (mm) sweeps from p0 to
  /// p1 (RAS, mm); BeginStroke/EndStroke group poses into one undo step.
  /// Return false, with the reason in the log, when the stroke is refused
  /// (bad pose or radius, no anatomy); what was cut before is kept.
  /// Each accepted cut, restore, undo or redo invokes the node's
  /// CutModifiedEvent, so call these from the thread that owns the scene; a
  /// haptic loop cuts the vtkVolumeCutField itself (no events) and views
  /// find the changed bricks by their stamps.
  bool BeginStroke(vtkMRMLVolumeCutNode* cutNode);
  bool CutSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius);
  bool RestoreSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius);
  bool EndStroke(vtkMRMLVolumeCutNode* cutNode);
  /// Any tool (cylinder, ellipsoid, blade, mesh, sawing prism) moving rigidly
  /// from pose0 to pose1 (tool-to-RAS).
  bool CutToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);
  bool RestoreToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);
  /// A region given as sampled signed distances on the anatomy's voxels
  /// minus voxels kept (vtkVolumeCutField::CutSampledRegion): a planned
  /// SoftCut resection (vtkSlicerVolumeCuttingSoftCutLogic), one undo step.
  bool CutSampledRegion(vtkMRMLVolumeCutNode* cutNode, vtkImageData* distances, vtkImageData* keep);
  /// Drill for dt seconds with rate-based material removal (seed 003): the
  /// node's anatomy gives bone density in HU; burrType is
  /// vtkVolumeCutMaterialRemoval::CuttingBurr or DiamondBurr. Exposure
  /// accumulates per node until ResetMaterialRemoval or a new cut field.
  bool DrillWithMaterialRemoval(vtkMRMLVolumeCutNode* cutNode, const double center[3], const double axis[3], double radius, double dt, int burrType);
  void ResetMaterialRemoval(vtkMRMLVolumeCutNode* cutNode);
  /// Strokes of the cut node's active tool node (vtkMRMLVolumeCutToolNode):
  /// its shape and sizes sweep rigidly from pose0 to pose1 (tool-to-RAS, in
  /// the tool's frame as the tool node documents it); a spherical burr sweeps
  /// as a capsule. What it may remove follows its sensibility (its own list
  /// of cuttable segments, or the cut node's roles): the shield is rebuilt
  /// from a table when the active tool or its list changes. Return false,
  /// with the reason in the log, without an active tool or a valid pose.
  bool CutWithActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);
  bool RestoreWithActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);
  /// What MoveActiveTool does along the way from the previous pose.
  enum ToolAction
  {
    ToolMove = 0,
    ToolCut,
    ToolRestore,
    /// The transform only: a tool whose strokes another thread cuts (a
    /// haptic session's), whose shield that thread's preparer builds; the
    /// caller must not touch the field the other thread writes.
    ToolFollow
  };
  /// Move the active tool to a pose, from any source (mouse, haptic device,
  /// replay): its transform node follows (views draw the tool there), and
  /// inside a stroke the tool cuts or restores along the way from its
  /// previous pose in the stroke. Returns false, with the reason in the log,
  /// without an active tool or for a pose that is not a rigid motion.
  bool MoveActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* toolToRAS, int action);
  /// Drill with rate-based material removal (see DrillWithMaterialRemoval)
  /// using the active tool's cutting radius, burr type and power (which scales the rate).
  bool DrillWithActiveTool(vtkMRMLVolumeCutNode* cutNode, const double center[3], const double axis[3], double dt);
  /// The cut node's active tool node, or nullptr.
  static vtkMRMLVolumeCutToolNode* GetActiveTool(vtkMRMLVolumeCutNode* cutNode);
  /// The cutting tool a non-spherical tool node describes (rebuilt when its
  /// geometry changes); nullptr for a spherical burr or a mesh tool without mesh.
  vtkVolumeCutTool* GetCuttingTool(vtkMRMLVolumeCutToolNode* toolNode);
  bool UndoStroke(vtkMRMLVolumeCutNode* cutNode);
  bool RedoStroke(vtkMRMLVolumeCutNode* cutNode);
  ///@}

  ///@{
  /// The virtual nerve monitor (seed 003) of a cut node: the distance from
  /// the active tool's surface to each monitored segment's smoothed surface,
  /// a level and a firing rate (vtkVolumeCutNerveMonitor). Monitored: the
  /// node's protected segments, unless SetMonitoredSegmentIDs chose others
  /// (an empty list goes back to the protected ones). MoveActiveTool updates
  /// it at every pose of the mouse or a replay, a haptic session at every
  /// tick (shown at display rate). Its distance fields are built on a worker
  /// thread when the monitored segments change: readings are "not ready"
  /// meanwhile, nothing waits (WaitForNerveMonitor does, for scripts and
  /// tests). A change of level invokes NerveMonitorLevelChangedEvent on the
  /// logic (call data: the cut node); readings are appended to the table
  /// GetNerveMonitorTableNode (Time in s, Segment, Name, Distance in mm,
  /// Level). nullptr when nothing is monitored or NerveMonitoring is off.
  vtkVolumeCutNerveMonitor* GetNerveMonitor(vtkMRMLVolumeCutNode* cutNode);
  void SetMonitoredSegmentIDs(vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds);
  std::vector<std::string> GetMonitoredSegmentIDs(vtkMRMLVolumeCutNode* cutNode);
  bool WaitForNerveMonitor(vtkMRMLVolumeCutNode* cutNode);
  vtkMRMLTableNode* GetNerveMonitorTableNode(vtkMRMLVolumeCutNode* cutNode);
  /// Take readings made elsewhere (a haptic tick's) as the monitor's current ones.
  VTK_WRAPEXCLUDE void UpdateNerveMonitorWithReadings(vtkMRMLVolumeCutNode* cutNode, const void* readings, int count);
  /// Whether MoveActiveTool updates the monitor. Default is on.
  vtkSetMacro(NerveMonitoring, bool);
  vtkGetMacro(NerveMonitoring, bool);
  vtkBooleanMacro(NerveMonitoring, bool);
  /// The helper that keeps the monitors and their tables.
  vtkSlicerVolumeCuttingNerveMonitors* GetNerveMonitors();
  enum Events
  {
    NerveMonitorLevelChangedEvent = vtkCommand::UserEvent + 2560
  };
  ///@}

  ///@{
  /// The bone left ahead of the active tool (mm), for the drill sound whose
  /// pitch rises as it thins (seed 003): measured from the tip of the
  /// cutting part (its half extent along the shaft) along the tool's axis,
  /// away from the handpiece (local -z), through the node's cuttable
  /// segments less what the cut field removed, as the renderer's thin-bone
  /// tint measures walls (vtkVolumeCutBoneAhead: quarter-voxel march, the
  /// crossings halved to 1/256 of a voxel). +inf when no bone begins within
  /// the query's Range (4 mm) ahead, at most its MaximumThickness (4 mm);
  /// +inf as well without an active tool or a cuttable segment with voxels
  /// (nothing can thin). The pose is the tool's own (its parent transform)
  /// unless given. GetBoneAhead gives the query, made from the segments'
  /// labels on the anatomy's grid when they change (nullptr: no bone).
  double MeasureBoneAhead(vtkMRMLVolumeCutNode* cutNode);
  double MeasureBoneAhead(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* toolToRAS);
  vtkVolumeCutBoneAhead* GetBoneAhead(vtkMRMLVolumeCutNode* cutNode);
  ///@}

  /// Volume (mm^3) removed inside a segment: the cut field's removed fraction
  /// of each anatomy voxel, summed over the segment's voxels (resampled to the
  /// anatomy's grid if needed). A shielded segment reports exactly 0 where
  /// the field did not remove its voxels' inside. The cost follows the size
  /// of the cut, not of the volume. Returns -1 and logs an error for an
  /// unknown segment or a node without segmentation.
  double GetRemovedVolumeInSegment(vtkMRMLVolumeCutNode* cutNode, const char* segmentId);

  /// The anatomy voxels with a removed fraction above zero (linear IJK index)
  /// and their fractions, computed once per change of the cut. False without a field.
  bool GetRemovedVoxels(vtkMRMLVolumeCutNode* cutNode, vtkIdTypeArray* voxelIds, vtkFloatArray* fractions);

  ///@{
  /// Tables the logic keeps up to date as the user drills, referenced by the
  /// cut node (saved with the scene, shown in Slicer's table views):
  /// the removed volume per segment (columns Segment, Name, Role, Removed
  /// volume in mm3), updated at the end of every stroke, undo and redo; and
  /// the contacts with segments a tool may not cut (Segment, Name, Time,
  /// Depth in mm, R, A, S), a row per stroke that touched one.
  /// Created on first request.
  vtkMRMLTableNode* GetRemovedVolumeTableNode(vtkMRMLVolumeCutNode* cutNode);
  vtkMRMLTableNode* GetContactTableNode(vtkMRMLVolumeCutNode* cutNode);
  /// Refill the removed-volume table now; returns it (nullptr without a field).
  vtkMRMLTableNode* UpdateRemovedVolumeTable(vtkMRMLVolumeCutNode* cutNode);
  static const char* GetRemovedVolumeTableReferenceRole() { return "removedVolumeTable"; }
  static const char* GetContactTableReferenceRole() { return "contactTable"; }
  ///@}

  /// Add a segmentation holding the removed region as one segment on the
  /// anatomy's grid: voxels at least half removed (binary labelmap). For
  /// display and export (STL, labelmap) with Slicer's segmentation tools.
  /// nullptr and an error if the node has no cut field.
  vtkMRMLSegmentationNode* ExportRemovedRegionToSegmentation(vtkMRMLVolumeCutNode* cutNode, const char* name = nullptr);

  /// The removed fraction (0..1) of each anatomy voxel as a float volume on
  /// the anatomy's grid: the fractional labelmap of the removed region.
  /// (Slicer-core's segmentation storage crashed reading back a segment whose
  /// source representation is a fractional labelmap, so this is a volume,
  /// which saves and reads like any other.)
  vtkMRMLScalarVolumeNode* ExportRemovedFractionToVolume(vtkMRMLVolumeCutNode* cutNode, const char* name = nullptr);

  /// The segment kept out of cutting (protected, or without a role) that a tool
  /// touched most deeply since the last ResetContact of the node's field ("" if
  /// none); the field gives the depth (mm) and position.
  std::string GetContactSegmentID(vtkMRMLVolumeCutNode* cutNode);

  /// Add a model of the removed region's closed boundary, contoured at
  /// sub-voxel resolution (save it as STL with Slicer's model storage).
  /// nullptr and an error if the node has no cut field.
  vtkMRMLModelNode* ExportRemovedSurfaceToModel(vtkMRMLVolumeCutNode* cutNode, const char* name = nullptr);

  /// Add the drilled CT: a copy of the anatomy in which each voxel is blended
  /// towards \a fillValue (air, -1000 HU) by its removed fraction, so fully
  /// removed voxels are air and partly removed ones keep partial volume.
  /// nullptr and an error if the node has no cut field.
  vtkMRMLScalarVolumeNode* ExportDrilledVolume(vtkMRMLVolumeCutNode* cutNode, double fillValue = -1000.0, const char* name = nullptr);

  /// Total removed volume (mm^3) of the node's cut field.
  double GetRemovedVolume(vtkMRMLVolumeCutNode* cutNode);

  /**
   * Label map of the given segments on the anatomy's voxel grid (unsigned
   * short, IJK geometry: label k + 1 for segmentIds[k], later segments win
   * where they overlap). Returns the IDs that could not be rasterised.
   * The displayable manager colours the cut rendering with it.
   */
  static std::vector<std::string> CreateSegmentLabelMap(
    vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds, vtkImageData* labels);

  /**
   * The fraction (0..1 float, anatomy grid, IJK geometry) of each anatomy
   * voxel inside a segment that has a fractional labelmap representation.
   * Returns false (nothing written) when the segment has none.
   */
  static bool CreateSegmentFractionOnAnatomyGrid(vtkMRMLVolumeCutNode* cutNode, const std::string& segmentId, vtkImageData* fraction);

protected:
  vtkSlicerVolumeCuttingLogic();
  ~vtkSlicerVolumeCuttingLogic() override;
  vtkSlicerVolumeCuttingLogic(const vtkSlicerVolumeCuttingLogic&) = delete;
  void operator=(const vtkSlicerVolumeCuttingLogic&) = delete;

  void RegisterNodes() override;

  /// Segments need the labelmap and closed-surface representations; desktop
  /// Slicer registers their conversion rules at start-up, a bare scene does not.
  static void RegisterSegmentationConverterRules();

  void OnMRMLSceneNodeRemoved(vtkMRMLNode* node) override;
  void OnMRMLSceneEndClose() override;
  void SetMRMLSceneInternal(vtkMRMLScene* newScene) override;

  /// The removed fraction of each anatomy voxel (see
  /// vtkVolumeCutField::ExportRemovedFraction), computed once per change of the
  /// field and shared by the exports of the removed region and fraction.
  vtkImageData* GetRemovedFraction(vtkMRMLVolumeCutNode* cutNode);

  /// Removed fractions by cut-node ID, with the field modification time they match.
  std::map<std::string, std::pair<vtkMTimeType, vtkSmartPointer<vtkImageData>>> RemovedFractions;

  /// The field for one pose: checked once per stroke, not per pose.
  vtkVolumeCutField* GetStrokeField(vtkMRMLVolumeCutNode* cutNode);
  /// Applies one pose (apply(field) returns whether it was accepted), as a
  /// stroke of its own outside BeginStroke/EndStroke, and notifies views.
  template <typename Apply>
  bool ApplyStroke(vtkMRMLVolumeCutNode* cutNode, Apply&& apply);
  /// Refresh the tables the user has after the cut changed.
  void UpdateTablesAfterChange(vtkMRMLVolumeCutNode* cutNode);
  /// Drop or clear what the logic keeps per cut node.
  void ForgetNode(const std::string& nodeId);
  void ForgetAllNodes();

  /// Invokes the node's CutModifiedEvent when \a changed and, when the tool
  /// went deeper into a shielded segment, its ProtectedContactEvent; returns \a changed.
  bool NotifyCutModified(vtkMRMLVolumeCutNode* cutNode, bool changed);

  /// Give the field the node's shielded segments from the segmentation's
  /// layers (a table change only, when the segmentation did not change).
  void UpdateProtection(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field, bool force = false);

  /// The segmentation's layers on the anatomy grid, per cut-node ID.
  vtkSlicerVolumeCuttingSegmentLayers* GetSegmentLayers(vtkMRMLVolumeCutNode* cutNode);
  std::map<std::string, vtkSmartPointer<vtkSlicerVolumeCuttingSegmentLayers>> SegmentLayers;

  /// The shielded segments each field's labels stand for (label n is element n - 1).
  std::map<std::string, std::vector<std::string>> ShieldedSegments;

  /// Removed voxels by cut-node ID, updated brick by brick as the cut changes.
  std::map<std::string, vtkSmartPointer<vtkVolumeCutRemovedVoxels>> RemovedVoxels;
  /// The up-to-date removed voxels of a node's field (nullptr without one).
  vtkVolumeCutRemovedVoxels* UpdateRemovedVoxels(vtkMRMLVolumeCutNode* cutNode);
  /// Removed volume (mm^3) of every segment of the node's segmentation, in one pass over the removed voxels.
  std::map<std::string, double> ComputeRemovedVolumePerSegment(vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds);

  /// The deepest contact reported in the open stroke, per cut-node ID.
  std::map<std::string, double> ReportedContactDepths;
  /// Add a row to the contact table if the stroke that ends touched a shielded segment.
  void RecordContact(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field);

  /// Sweep the active tool between two poses (cut or restore).
  bool SweepActiveTool(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1, bool cut);
  /// Cutting tools of the tool nodes, built once per change of a tool node.
  vtkSmartPointer<vtkSlicerVolumeCuttingToolCache> ToolCache;
  /// Nerve monitors and their tables, per cut node.
  vtkSmartPointer<vtkSlicerVolumeCuttingNerveMonitors> NerveMonitors;
  bool NerveMonitoring = true;
  /// New readings for the active tool at a pose; invokes the event on a change of level.
  void UpdateNerveMonitor(vtkMRMLVolumeCutNode* cutNode, vtkMatrix4x4* toolToRAS);
  /// The bone-ahead query of each cut node and what its bone was made from, per cut-node ID.
  struct BoneAheadQuery
  {
    std::string Source;
    vtkSmartPointer<vtkVolumeCutBoneAhead> Query;
  };
  std::map<std::string, BoneAheadQuery> BoneAheadQueries;

  /// The active tool's last pose in the open stroke, per cut-node ID.
  std::map<std::string, vtkSmartPointer<vtkMatrix4x4>> StrokePoses;

  /// Rate-based removal state per cut-node ID (its field and anatomy are inputs).
  std::map<std::string, vtkSmartPointer<vtkVolumeCutMaterialRemoval>> MaterialRemovals;

  /// What the protection of each field was last built from.
  std::map<std::string, std::string> ProtectionSources;

};

#endif
