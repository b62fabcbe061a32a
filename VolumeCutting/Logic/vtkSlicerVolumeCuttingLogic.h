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
#include <string>
#include <vector>

// VTK includes
#include <vtkSmartPointer.h>


#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

class vtkMRMLMessageCollection;
class vtkMRMLModelNode;
class vtkMRMLScalarVolumeNode;
class vtkMRMLSegmentationNode;
class vtkMRMLVolumeCutNode;
class vtkImageData;
class vtkMatrix4x4;
class vtkVolumeCutField;
class vtkVolumeCutMaterialRemoval;
class vtkVolumeCutTool;

/// \brief Builds and checks volume-cutting sessions.
///
/// The logic is thin on purpose: algorithms live in the Slicer-independent
/// vtkVolumeCuttingCore library, and this class connects them to MRML nodes.
/// Any source of work (the module widget, a Python script, a replay) uses the
/// same methods, so they are tested without a GUI.
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

  /// The cut field of a cut node (held by the node, saved with the scene):
  /// created on first use on the anatomy's voxel grid at the node's sub-voxel
  /// factor, and created anew (empty) when the
  /// anatomy's geometry or the factor changes. Its protection follows the
  /// node's protected segments (labels 1, 2, ... in the order of
  /// GetProtectedSegmentIDs), updated when they or the segmentation change.
  /// nullptr (and an error) when the node has no anatomy with voxels.
  vtkVolumeCutField* GetCutField(vtkMRMLVolumeCutNode* cutNode);

  ///@{
  /// Strokes from any source (mouse, haptic device, replay) go through here.
  /// A stroke of a spherical burr of the given radius (mm) sweeps from p0 to
  /// p1 (RAS, mm); BeginStroke/EndStroke group poses into one undo step.
  /// Return false, with the reason in the log, when the stroke is refused
  /// (bad pose or radius, no anatomy); what was cut before is kept.
  /// Each accepted cut, restore, undo or redo invokes the node's
  /// CutModifiedEvent, so call these from the thread that owns the scene; a
  /// haptic thread cuts the vtkVolumeCutField itself (no events) and views
  /// find the changed bricks by their stamps.
  bool BeginStroke(vtkMRMLVolumeCutNode* cutNode);
  bool CutSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius);
  bool RestoreSphereSweep(vtkMRMLVolumeCutNode* cutNode, const double p0[3], const double p1[3], double radius);
  bool EndStroke(vtkMRMLVolumeCutNode* cutNode);
  /// Any tool (cylinder, ellipsoid, blade, mesh, sawing prism) moving rigidly
  /// from pose0 to pose1 (tool-to-RAS).
  bool CutToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);
  bool RestoreToolSweep(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutTool* tool, vtkMatrix4x4* pose0, vtkMatrix4x4* pose1);
  /// Drill for dt seconds with rate-based material removal (seed 003): the
  /// node's anatomy gives bone density in HU; burrType is
  /// vtkVolumeCutMaterialRemoval::CuttingBurr or DiamondBurr. Exposure
  /// accumulates per node until ResetMaterialRemoval or a new cut field.
  bool DrillWithMaterialRemoval(vtkMRMLVolumeCutNode* cutNode, const double center[3], const double axis[3], double radius, double dt, int burrType);
  void ResetMaterialRemoval(vtkMRMLVolumeCutNode* cutNode);
  bool UndoStroke(vtkMRMLVolumeCutNode* cutNode);
  bool RedoStroke(vtkMRMLVolumeCutNode* cutNode);
  ///@}

  /// Volume (mm^3) removed inside a segment: the cut field's removed fraction
  /// of each anatomy voxel, summed over the segment's voxels (resampled to the
  /// anatomy's grid if needed). Returns -1 and logs an error for an unknown
  /// segment or a node without segmentation.
  double GetRemovedVolumeInSegment(vtkMRMLVolumeCutNode* cutNode, const char* segmentId);

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
  /// field and shared by the per-segment volumes and the exports.
  vtkImageData* GetRemovedFraction(vtkMRMLVolumeCutNode* cutNode);

  /// Add a scalar volume holding \a image on the anatomy's voxel grid.
  vtkMRMLScalarVolumeNode* AddVolumeOnAnatomyGrid(vtkMRMLScalarVolumeNode* anatomy, vtkImageData* image, const std::string& name);

  /// Removed fractions by cut-node ID, with the field modification time they match.
  std::map<std::string, std::pair<vtkMTimeType, vtkSmartPointer<vtkImageData>>> RemovedFractions;

  /// The field for one pose: checked once per stroke, not per pose.
  vtkVolumeCutField* GetStrokeField(vtkMRMLVolumeCutNode* cutNode);

  /// Segments kept out of cutting, in label order (label n is element n - 1).
  static std::vector<std::string> GetShieldedSegmentIDs(vtkMRMLVolumeCutNode* cutNode);
  /// Invokes the node's CutModifiedEvent when \a changed; returns \a changed.
  static bool NotifyCutModified(vtkMRMLVolumeCutNode* cutNode, bool changed);

  /// Give the field the node's shielded segments as labels on the anatomy grid.
  void UpdateProtection(vtkMRMLVolumeCutNode* cutNode, vtkVolumeCutField* field);

  /// Rate-based removal state per cut-node ID (its field and anatomy are inputs).
  std::map<std::string, vtkSmartPointer<vtkVolumeCutMaterialRemoval>> MaterialRemovals;

  /// What the protection of each field was last built from.
  std::map<std::string, std::string> ProtectionSources;

};

#endif
