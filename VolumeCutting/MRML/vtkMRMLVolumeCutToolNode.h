/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkMRMLVolumeCutToolNode_h
#define vtkMRMLVolumeCutToolNode_h

// MRML includes
#include <vtkMRMLDisplayableNode.h>

// STD includes
#include <string>
#include <vector>

#include "vtkSlicerVolumeCuttingModuleMRMLExport.h"

class vtkMRMLModelNode;
class vtkMRMLVolumeCutNode;
class vtkMRMLVolumeCutToolDisplayNode;

/// \brief A cutting tool: a burr, a saw or a mesh, its size, drive and sensibility.
///
/// The tool's pose is its parent transform (SetAndObserveTransformNodeID): the
/// transform maps the tool's local frame to RAS. In the local frame the
/// cutting part is centred on the origin and the shaft (rotation axis) is the
/// z axis, pointing from the cutting part towards the handpiece:
/// - Sphere: a round burr of diameter Diameter;
/// - Cylinder: a cylindrical (side-cutting, "matchstick") burr, Diameter
///   across, Length along z;
/// - DiskSaw: a disk of diameter Diameter in the xy plane, Thickness along z;
/// - Blade: a sagittal saw blade, Width along x, Thickness along y, Length
///   along z;
/// - Mesh: the closed surface of the referenced model node, in local
///   coordinates.
///
/// Sizes are in millimetres. Each setter rejects a value outside its valid
/// range with an error and keeps the previous value; the ranges are public
/// (GetMinimumDiameter(), ...) so that user interfaces offer the same limits.
///
/// Sensibility (which segments this tool may remove): by default the tool
/// follows the volume-cut node's roles (UseCutNodeRoles). Without them, it
/// may remove the segments listed in CuttableSegmentIDs. Protection always
/// wins: a segment the volume-cut node protects is never the tool's to cut,
/// whatever its own list says (MayCutSegment()).
///
/// The node holds no cutting algorithm: the logic builds the matching
/// vtkVolumeCutTool from these properties.
///
/// \sa vtkMRMLVolumeCutToolDisplayNode, vtkMRMLVolumeCutNode
class VTK_SLICER_VOLUMECUTTING_MODULE_MRML_EXPORT vtkMRMLVolumeCutToolNode : public vtkMRMLDisplayableNode
{
public:
  static vtkMRMLVolumeCutToolNode* New();
  vtkTypeMacro(vtkMRMLVolumeCutToolNode, vtkMRMLDisplayableNode);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkMRMLNode* CreateNodeInstance() override;
  const char* GetNodeTagName() override { return "VolumeCutTool"; }

  void ReadXMLAttributes(const char** atts) override;
  void WriteXML(ostream& of, int indent) override;
  vtkMRMLCopyContentMacro(vtkMRMLVolumeCutToolNode);

  void ProcessMRMLEvents(vtkObject* caller, unsigned long event, void* callData) override;

  /// Create a vtkMRMLVolumeCutToolDisplayNode in the node's scene and observe
  /// it, unless the node has one already. The display node class must be
  /// registered in the scene (the module logic does it).
  void CreateDefaultDisplayNodes() override;

  /// The first display node, if it is a tool display node.
  vtkMRMLVolumeCutToolDisplayNode* GetVolumeCutToolDisplayNode();

  enum
  {
    /// Invoked when what the tool removes changes: the shape, a size or the
    /// mesh (its reference or its points). Not for power, speed or
    /// sensibility, so that the logic rebuilds the tool only when needed.
    ToolGeometryModifiedEvent = 27310
  };

  enum ShapeType
  {
    Sphere = 0,
    Cylinder,
    DiskSaw,
    Blade,
    Mesh,
    Shape_Last
  };

  enum BurrTypeType
  {
    /// Fluted steel or carbide burr: removes bone fast, more so at its equator.
    Cutting = 0,
    /// Diamond-coated burr: slower and more even, used near critical structures.
    Diamond,
    BurrType_Last
  };

  ///@{
  /// Shape of the cutting part (ShapeType). Invalid values are rejected with
  /// an error. Changing the shape brings the diameter into the new shape's
  /// range (set the diameter after the shape). Default is Sphere.
  vtkGetMacro(Shape, int);
  void SetShape(int shape);
  static const char* GetShapeAsString(int shape);
  /// Returns -1 for an unknown name.
  static int GetShapeFromString(const char* name);
  ///@}

  ///@{
  /// Burr type (BurrTypeType): how a rotating burr removes bone (the
  /// material-removal model of vtkVolumeCutMaterialRemoval uses the same
  /// values). Invalid values are rejected with an error. Default is Cutting.
  vtkGetMacro(BurrType, int);
  void SetBurrType(int burrType);
  static const char* GetBurrTypeAsString(int burrType);
  /// Returns -1 for an unknown name.
  static int GetBurrTypeFromString(const char* name);
  ///@}

  ///@{
  /// Diameter (mm) of a burr (1 to 7 mm) or of a disk saw (5 to 60 mm).
  /// Blades and meshes do not use it; it keeps a burr's range for them.
  /// Values outside the current shape's range are rejected with an error.
  /// Default is 4.
  vtkGetMacro(Diameter, double);
  void SetDiameter(double diameter);
  static double GetMinimumDiameter(int shape);
  static double GetMaximumDiameter(int shape);
  ///@}

  ///@{
  /// Length (mm) of a cylindrical burr's cutting part or of a blade, along
  /// the shaft. Valid range 0.5 to 100. Default is 6.
  vtkGetMacro(Length, double);
  void SetLength(double length);
  static double GetMinimumLength();
  static double GetMaximumLength();
  ///@}

  ///@{
  /// Thickness (mm) of a disk saw or a blade. Valid range 0.1 to 5.
  /// Default is 0.5.
  vtkGetMacro(Thickness, double);
  void SetThickness(double thickness);
  static double GetMinimumThickness();
  static double GetMaximumThickness();
  ///@}

  ///@{
  /// Width (mm) of a blade, across its cutting edge. Valid range 1 to 50.
  /// Default is 10.
  vtkGetMacro(Width, double);
  void SetWidth(double width);
  static double GetMinimumWidth();
  static double GetMaximumWidth();
  ///@}

  ///@{
  /// Drive power as a fraction (0 to 1) of the handpiece's maximum, as the
  /// foot pedal sets it. Default is 1.
  vtkGetMacro(Power, double);
  void SetPower(double power);
  ///@}

  ///@{
  /// Speed at full power: revolutions per minute of a burr or disk saw,
  /// oscillations per minute of a blade. Valid range 0 to 150000 (the
  /// fastest otologic drills reach about 100000 rpm). Default is 60000.
  vtkGetMacro(Speed, double);
  void SetSpeed(double speed);
  static double GetMaximumSpeed();
  ///@}

  ///@{
  /// Whether the tool cuts what the volume-cut node's roles allow (true) or
  /// the segments of CuttableSegmentIDs (false). Default is true.
  vtkGetMacro(UseCutNodeRoles, bool);
  vtkSetMacro(UseCutNodeRoles, bool);
  vtkBooleanMacro(UseCutNodeRoles, bool);
  ///@}

  ///@{
  /// Segments this tool may remove when it does not follow the cut node's
  /// roles. Duplicates and empty IDs are dropped. Empty by default.
  void SetCuttableSegmentIDs(const std::vector<std::string>& segmentIds);
  std::vector<std::string> GetCuttableSegmentIDs() const { return this->CuttableSegmentIDs; }
  /// Add a segment to the list or remove it from it.
  void SetSegmentCuttable(const std::string& segmentId, bool cuttable);
  /// Whether the segment is in this tool's own list (whatever UseCutNodeRoles says).
  bool IsSegmentInCuttableList(const std::string& segmentId) const;
  ///@}

  ///@{
  /// The tool's sensibility against a cut node: whether this tool may remove
  /// the segment, and every segment of the cut node's segmentation it may
  /// remove. A segment the cut node protects is never cuttable. Without a cut
  /// node, only the tool's own list counts (and nothing when it follows the
  /// cut node's roles).
  bool MayCutSegment(vtkMRMLVolumeCutNode* cutNode, const std::string& segmentId);
  std::vector<std::string> GetEffectiveCuttableSegmentIDs(vtkMRMLVolumeCutNode* cutNode);
  ///@}

  ///@{
  /// Closed surface of a Mesh tool, in the tool's local coordinates.
  void SetAndObserveMeshModelNodeID(const char* nodeId);
  const char* GetMeshModelNodeID();
  vtkMRMLModelNode* GetMeshModelNode();
  ///@}

  /// Radius (mm) of the cutting part around the shaft: half the diameter of a
  /// burr or disk saw, half the width of a blade, the bounding radius of a mesh.
  double GetCuttingRadius();

  /// Radius (mm) of the smallest origin-centred sphere that contains the
  /// cutting part (0 for a Mesh tool without a surface).
  double GetBoundingRadius();

protected:
  vtkMRMLVolumeCutToolNode();
  ~vtkMRMLVolumeCutToolNode() override;
  vtkMRMLVolumeCutToolNode(const vtkMRMLVolumeCutToolNode&) = delete;
  void operator=(const vtkMRMLVolumeCutToolNode&) = delete;

  /// Set a value if it is finite and within [minimum, maximum]; otherwise log
  /// an error naming the property and keep the value. A change of a geometry
  /// property also invokes ToolGeometryModifiedEvent.
  void SetValidatedValue(double& member, double value, double minimum, double maximum, const char* property, bool geometry);

  /// A new, changed or removed mesh reference changes what the tool removes.
  void OnNodeReferenceAdded(vtkMRMLNodeReference* reference) override;
  void OnNodeReferenceModified(vtkMRMLNodeReference* reference) override;
  void OnNodeReferenceRemoved(vtkMRMLNodeReference* reference) override;
  void InvokeGeometryModifiedIfMesh(vtkMRMLNodeReference* reference);

  static const char* MeshModelReferenceRole;

  int Shape{ Sphere };
  int BurrType{ Cutting };
  double Diameter{ 4.0 };
  double Length{ 6.0 };
  double Thickness{ 0.5 };
  double Width{ 10.0 };
  double Power{ 1.0 };
  double Speed{ 60000.0 };
  bool UseCutNodeRoles{ true };
  std::vector<std::string> CuttableSegmentIDs;
};

#endif
