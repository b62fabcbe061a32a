/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkMRMLVolumeCutNode_h
#define vtkMRMLVolumeCutNode_h

// MRML includes
#include <vtkMRMLStorableNode.h>
#include <vtkSmartPointer.h>

// STD includes
#include <string>
#include <vector>

#include "vtkSlicerVolumeCuttingModuleMRMLExport.h"

class vtkMRMLScalarVolumeNode;
class vtkMRMLSegmentationNode;
class vtkVolumeCutField;

/// \brief Parameters of one volume-cutting session on one anatomy.
///
/// The node ties the anatomy (a CT as a scalar volume and its segmentation) to
/// what the tools may do with it: which segments a tool may cut, which are
/// protected (critical structures such as the facial nerve, which are never
/// removed), the sub-voxel factor of the cut field, and the active tool.
///
/// The anatomy itself is never modified by cutting: the removed region lives in
/// a separate cut field (multivolume scheme of Pflesser et al., 2002), so the
/// node only references the anatomy.
///
/// Tool sensibility: tools remove only cuttable segments (and voxels outside
/// every segment). Protected segments are the critical structures whose
/// contact matters; segments without a role are left alone too.
/// A segment has at most one role: setting a segment cuttable clears its
/// protected role and vice versa. Roles refer to segment IDs of the referenced
/// segmentation; when a segment is removed from it, its role is dropped.
///
/// \sa vtkSlicerVolumeCuttingLogic
class VTK_SLICER_VOLUMECUTTING_MODULE_MRML_EXPORT vtkMRMLVolumeCutNode : public vtkMRMLStorableNode
{
public:
  static vtkMRMLVolumeCutNode* New();
  vtkTypeMacro(vtkMRMLVolumeCutNode, vtkMRMLStorableNode);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkMRMLNode* CreateNodeInstance() override;
  const char* GetNodeTagName() override { return "VolumeCut"; }

  void ReadXMLAttributes(const char** atts) override;
  void WriteXML(ostream& of, int indent) override;
  vtkMRMLCopyContentMacro(vtkMRMLVolumeCutNode);

  void ProcessMRMLEvents(vtkObject* caller, unsigned long event, void* callData) override;

  enum
  {
    /// Invoked when the content of a referenced input (anatomy voxels or
    /// segments) changes, so that derived data (cut field geometry,
    /// renderer inputs) can be updated.
    InputDataModifiedEvent = 27300,
    /// Invoked when the role of any segment changes.
    SegmentRolesModifiedEvent,
    /// Invoked (by the logic, on the thread that cuts through it) when the
    /// removed region changed: views re-render the modified bricks.
    CutModifiedEvent,
    /// Invoked (by the logic) when a tool went deeper into a segment it may
    /// not cut: the logic's GetContactSegmentID and the field's contact depth
    /// and position say where. A GUI highlights it at once.
    ProtectedContactEvent,
    /// Invoked (by the logic, on the main thread) when a stroke begins (the
    /// drill pressed with the mouse or a device) and when it ends: views draw
    /// reduced images while it lasts and the full image after.
    StrokeStartedEvent,
    StrokeEndedEvent
  };

  ///@{
  /// The removed region. The node holds it so that it is saved and read with
  /// the scene (vtkMRMLVolumeCutStorageNode, .vcut); the logic creates it on
  /// the anatomy's grid. Changes of the field mark the node modified for saving.
  vtkVolumeCutField* GetCutField() { return this->CutField; }
  void SetCutField(vtkVolumeCutField* field);
  ///@}

  ///@{
  /// A second removed region shown in 3D views with the cut field but not
  /// part of the cut: a preview (a SoftCut resection at the depth being
  /// chosen, vtkSlicerVolumeCuttingSoftCutLogic). Not saved, copied or
  /// undone with the node; nullptr (the default) for none. Setting it
  /// invokes CutModifiedEvent.
  vtkVolumeCutField* GetPreviewCutField();
  void SetPreviewCutField(vtkVolumeCutField* field);
  ///@}

  vtkMRMLStorageNode* CreateDefaultStorageNode() override;
  std::string GetDefaultStorageNodeClassName(const char* filename = nullptr) override;

  ///@{
  /// Anatomy volume (CT in Hounsfield units) the cut field is aligned with.
  void SetAndObserveAnatomyVolumeNodeID(const char* nodeId);
  const char* GetAnatomyVolumeNodeID();
  vtkMRMLScalarVolumeNode* GetAnatomyVolumeNode();
  ///@}

  ///@{
  /// Segmentation of the anatomy whose segments receive roles.
  void SetAndObserveSegmentationNodeID(const char* nodeId);
  const char* GetSegmentationNodeID();
  vtkMRMLSegmentationNode* GetSegmentationNode();
  ///@}

  ///@{
  /// Node that describes the active cutting tool (shape, size, sensibility).
  void SetAndObserveActiveToolNodeID(const char* nodeId);
  const char* GetActiveToolNodeID();
  vtkMRMLNode* GetActiveToolNode();
  ///@}

  ///@{
  /// Segments a tool may remove. An ID that is also protected is dropped from
  /// this list: protection wins, since removing a critical structure is the
  /// error the user must never be exposed to.
  void SetCuttableSegmentIDs(const std::vector<std::string>& segmentIds);
  std::vector<std::string> GetCuttableSegmentIDs() const { return this->CuttableSegmentIDs; }
  ///@}

  ///@{
  /// Segments that are never removed and whose contact is reported.
  void SetProtectedSegmentIDs(const std::vector<std::string>& segmentIds);
  std::vector<std::string> GetProtectedSegmentIDs() const { return this->ProtectedSegmentIDs; }
  ///@}

  ///@{
  /**
   * Segments made of one material (cortical and trabecular bone): their
   * uncut surfaces are drawn in the colour of the first of them, as one
   * bone; where a cut or clip plane opens them, each shows its own colour, so
   * the cut surface tells which segment it exposes. Empty by default (every
   * segment in its own colour).
   */
  void SetMaterialSegmentIDs(const std::vector<std::string>& segmentIds);
  std::vector<std::string> GetMaterialSegmentIDs() const { return this->MaterialSegmentIDs; }
  ///@}

  ///@{
  /// Give a segment the cuttable or protected role, or take it away.
  /// Returns false, logs an error and changes nothing if no segmentation is
  /// referenced or the segmentation has no segment with this ID.
  bool SetSegmentCuttable(const std::string& segmentId, bool cuttable);
  bool SetSegmentProtected(const std::string& segmentId, bool isProtected);
  bool IsSegmentCuttable(const std::string& segmentId) const;
  bool IsSegmentProtected(const std::string& segmentId) const;
  ///@}

  ///@{
  /// Resolution of the cut field relative to the anatomy's voxels along each
  /// axis: 1, 2 or 4. Other values are rejected with an error.
  /// Default is 2.
  void SetSubVoxelFactor(int factor);
  vtkGetMacro(SubVoxelFactor, int);
  static bool IsValidSubVoxelFactor(int factor);

  ///@{
  /**
   * How the 3D view shows the cut anatomy (vtkMRMLVolumeCutDisplayableManager):
   * the CT value (HU) of the surface of cuttable segments (and of the bone
   * when there is no segmentation), and thin-bone shading (Morris et al.):
   * bone thinner than ThinBoneThickness (mm) shown red and translucent.
   */
  vtkSetMacro(SurfaceIsoValue, double);
  vtkGetMacro(SurfaceIsoValue, double);
  vtkSetMacro(ThinBoneShading, bool);
  vtkGetMacro(ThinBoneShading, bool);
  vtkBooleanMacro(ThinBoneShading, bool);
  vtkSetClampMacro(ThinBoneThickness, double, 0.05, 20.0);
  vtkGetMacro(ThinBoneThickness, double);
  ///@}

  ///@{
  /**
   * Ambient occlusion in the 3D view: a depth cue that darkens cavities
   * (vtkVolumeCutRayCaster::SetAmbientOcclusion). Default is true.
   */
  vtkSetMacro(AmbientOcclusion, bool);
  vtkGetMacro(AmbientOcclusion, bool);
  vtkBooleanMacro(AmbientOcclusion, bool);
  ///@}

  ///@{
  /**
   * Standard deviation (voxels) of the smoothing of segments drawn from
   * binary labelmaps by their own shape, so that they look as smooth as
   * Slicer's closed surfaces of them (vtkVolumeCutRayCaster::SetLabelSmoothing);
   * 0 shows the voxels. Default is 1.
   */
  vtkSetClampMacro(LabelSmoothing, double, 0.0, 8.0);
  vtkGetMacro(LabelSmoothing, double);
  ///@}
  ///@}

  ///@{
  /**
   * How 2D slice views show the removed region where they cut it
   * (vtkMRMLVolumeCutSliceDisplayableManager): its outline where the slice
   * plane meets the cut surface, SliceOutlineThickness pixels wide (default
   * 2), and a fill of the removed part of the plane at SliceFillOpacity
   * (default 0.3), both in SliceColor (default a clear red, 1, 0.15, 0.1).
   * Outline and fill are visible by default.
   */
  vtkSetMacro(SliceOutlineVisibility, bool);
  vtkGetMacro(SliceOutlineVisibility, bool);
  vtkBooleanMacro(SliceOutlineVisibility, bool);
  vtkSetMacro(SliceFillVisibility, bool);
  vtkGetMacro(SliceFillVisibility, bool);
  vtkBooleanMacro(SliceFillVisibility, bool);
  vtkSetClampMacro(SliceFillOpacity, double, 0.0, 1.0);
  vtkGetMacro(SliceFillOpacity, double);
  vtkSetVector3Macro(SliceColor, double);
  vtkGetVector3Macro(SliceColor, double);
  vtkSetClampMacro(SliceOutlineThickness, double, 0.1, 100.0);
  vtkGetMacro(SliceOutlineThickness, double);
  ///@}

protected:
  vtkMRMLVolumeCutNode();
  ~vtkMRMLVolumeCutNode() override;
  vtkMRMLVolumeCutNode(const vtkMRMLVolumeCutNode&) = delete;
  void operator=(const vtkMRMLVolumeCutNode&) = delete;

  /// Whether the referenced segmentation has this segment; logs an error if not.
  bool CheckSegmentExists(const std::string& segmentId, const char* caller);
  void RemoveSegmentRoles(const std::string& segmentId);

  static const char* AnatomyVolumeReferenceRole;
  static const char* SegmentationReferenceRole;
  static const char* ActiveToolReferenceRole;

  vtkVolumeCutField* CutField{ nullptr };
  vtkSmartPointer<vtkVolumeCutField> PreviewCutField;
  std::vector<std::string> CuttableSegmentIDs;
  std::vector<std::string> ProtectedSegmentIDs;
  std::vector<std::string> MaterialSegmentIDs;
  int SubVoxelFactor{ 2 };
  double SurfaceIsoValue{ 300.0 };
  bool ThinBoneShading{ false };
  double ThinBoneThickness{ 1.0 };
  bool AmbientOcclusion{ true };
  double LabelSmoothing{ 1.0 };

  bool SliceOutlineVisibility{ true };
  bool SliceFillVisibility{ true };
  double SliceFillOpacity{ 0.3 };
  double SliceColor[3]{ 1.0, 0.15, 0.1 };
  double SliceOutlineThickness{ 2.0 };
};

#endif
