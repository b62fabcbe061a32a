/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkMRMLVolumeCutToolNode.h"
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutToolDisplayNode.h"

// MRML includes
#include <vtkMRMLModelNode.h>
#include <vtkMRMLNodePropertyMacros.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkSegmentation.h>

// VTK includes
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointSet.h>
#include <vtkPoints.h>

// STD includes
#include <algorithm>
#include <cmath>
#include <cstring>

const char* vtkMRMLVolumeCutToolNode::MeshModelReferenceRole = "meshModel";

namespace
{
// Burrs of otologic and spine drilling; disk saws of the same handpieces.
constexpr double BurrDiameterRange[2] = { 1.0, 7.0 };
constexpr double DiskSawDiameterRange[2] = { 5.0, 60.0 };
constexpr double LengthRange[2] = { 0.5, 100.0 };
constexpr double ThicknessRange[2] = { 0.1, 5.0 };
constexpr double WidthRange[2] = { 1.0, 50.0 };
constexpr double MaximumSpeed = 150000.0;

/// The value whose name is `name`, or -1: the inverse of an AsString function.
int EnumFromString(const char* name, int count, const char* (*asString)(int))
{
  for (int value = 0; name && value < count; ++value)
  {
    if (!strcmp(name, asString(value)))
    {
      return value;
    }
  }
  return -1;
}

bool Contains(const std::vector<std::string>& ids, const std::string& id)
{
  return std::find(ids.begin(), ids.end(), id) != ids.end();
}
} // namespace

//----------------------------------------------------------------------------
vtkMRMLNodeNewMacro(vtkMRMLVolumeCutToolNode);

//----------------------------------------------------------------------------
vtkMRMLVolumeCutToolNode::vtkMRMLVolumeCutToolNode()
{
  // Choosing a burr or a size is a user edit worth undoing, as in Slicer's
  // own displayable nodes.
  this->SetUndoEnabled(true);

  vtkNew<vtkIntArray> meshEvents;
  meshEvents->InsertNextValue(vtkMRMLModelNode::MeshModifiedEvent);
  this->AddNodeReferenceRole(MeshModelReferenceRole, "meshModelRef", meshEvents);
}

//----------------------------------------------------------------------------
vtkMRMLVolumeCutToolNode::~vtkMRMLVolumeCutToolNode() = default;

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::WriteXML(ostream& of, int nIndent)
{
  Superclass::WriteXML(of, nIndent);
  vtkMRMLWriteXMLBeginMacro(of);
  // Shape before diameter: the diameter's valid range depends on the shape.
  vtkMRMLWriteXMLEnumMacro(shape, Shape);
  vtkMRMLWriteXMLEnumMacro(burrType, BurrType);
  vtkMRMLWriteXMLFloatMacro(diameter, Diameter);
  vtkMRMLWriteXMLFloatMacro(length, Length);
  vtkMRMLWriteXMLFloatMacro(thickness, Thickness);
  vtkMRMLWriteXMLFloatMacro(width, Width);
  vtkMRMLWriteXMLFloatMacro(power, Power);
  vtkMRMLWriteXMLFloatMacro(speed, Speed);
  vtkMRMLWriteXMLBooleanMacro(useCutNodeRoles, UseCutNodeRoles);
  vtkMRMLWriteXMLStdStringVectorMacro(cuttableSegmentIDs, CuttableSegmentIDs, std::vector);
  vtkMRMLWriteXMLEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::ReadXMLAttributes(const char** atts)
{
  MRMLNodeModifyBlocker blocker(this);
  Superclass::ReadXMLAttributes(atts);
  // The diameter's valid range depends on the shape: take the shape first,
  // whatever the order of the attributes in a hand-edited file. A bad shape is
  // reported once, below.
  for (const char** att = atts; att && att[0] && att[1]; att += 2)
  {
    if (!strcmp(att[0], "shape") && GetShapeFromString(att[1]) >= 0)
    {
      this->SetShape(GetShapeFromString(att[1]));
    }
  }
  vtkMRMLReadXMLBeginMacro(atts);
  vtkMRMLReadXMLEnumMacro(shape, Shape);
  vtkMRMLReadXMLEnumMacro(burrType, BurrType);
  vtkMRMLReadXMLFloatMacro(diameter, Diameter);
  vtkMRMLReadXMLFloatMacro(length, Length);
  vtkMRMLReadXMLFloatMacro(thickness, Thickness);
  vtkMRMLReadXMLFloatMacro(width, Width);
  vtkMRMLReadXMLFloatMacro(power, Power);
  vtkMRMLReadXMLFloatMacro(speed, Speed);
  vtkMRMLReadXMLBooleanMacro(useCutNodeRoles, UseCutNodeRoles);
  vtkMRMLReadXMLStdStringVectorMacro(cuttableSegmentIDs, CuttableSegmentIDs, std::vector);
  vtkMRMLReadXMLEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::CopyContent(vtkMRMLNode* anode, bool deepCopy /*=true*/)
{
  MRMLNodeModifyBlocker blocker(this);
  Superclass::CopyContent(anode, deepCopy);
  vtkMRMLCopyBeginMacro(anode);
  vtkMRMLCopyEnumMacro(Shape);
  vtkMRMLCopyEnumMacro(BurrType);
  vtkMRMLCopyFloatMacro(Diameter);
  vtkMRMLCopyFloatMacro(Length);
  vtkMRMLCopyFloatMacro(Thickness);
  vtkMRMLCopyFloatMacro(Width);
  vtkMRMLCopyFloatMacro(Power);
  vtkMRMLCopyFloatMacro(Speed);
  vtkMRMLCopyBooleanMacro(UseCutNodeRoles);
  vtkMRMLCopyStdStringVectorMacro(CuttableSegmentIDs);
  vtkMRMLCopyEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::PrintSelf(ostream& os, vtkIndent indent)
{
  Superclass::PrintSelf(os, indent);
  vtkMRMLPrintBeginMacro(os, indent);
  vtkMRMLPrintEnumMacro(Shape);
  vtkMRMLPrintEnumMacro(BurrType);
  vtkMRMLPrintFloatMacro(Diameter);
  vtkMRMLPrintFloatMacro(Length);
  vtkMRMLPrintFloatMacro(Thickness);
  vtkMRMLPrintFloatMacro(Width);
  vtkMRMLPrintFloatMacro(Power);
  vtkMRMLPrintFloatMacro(Speed);
  vtkMRMLPrintBooleanMacro(UseCutNodeRoles);
  vtkMRMLPrintStdStringVectorMacro(CuttableSegmentIDs, std::vector);
  vtkMRMLPrintEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::ProcessMRMLEvents(vtkObject* caller, unsigned long event, void* callData)
{
  Superclass::ProcessMRMLEvents(caller, event, callData);
  if (caller != nullptr && caller == this->GetMeshModelNode() && event == vtkMRMLModelNode::MeshModifiedEvent)
  {
    this->InvokeCustomModifiedEvent(ToolGeometryModifiedEvent);
  }
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::OnNodeReferenceAdded(vtkMRMLNodeReference* reference)
{
  Superclass::OnNodeReferenceAdded(reference);
  this->InvokeGeometryModifiedIfMesh(reference);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::OnNodeReferenceModified(vtkMRMLNodeReference* reference)
{
  Superclass::OnNodeReferenceModified(reference);
  this->InvokeGeometryModifiedIfMesh(reference);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::OnNodeReferenceRemoved(vtkMRMLNodeReference* reference)
{
  Superclass::OnNodeReferenceRemoved(reference);
  this->InvokeGeometryModifiedIfMesh(reference);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::InvokeGeometryModifiedIfMesh(vtkMRMLNodeReference* reference)
{
  if (reference && reference->GetReferenceRole() && !strcmp(reference->GetReferenceRole(), MeshModelReferenceRole))
  {
    this->InvokeCustomModifiedEvent(ToolGeometryModifiedEvent);
  }
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::CreateDefaultDisplayNodes()
{
  if (vtkMRMLVolumeCutToolDisplayNode::SafeDownCast(this->GetDisplayNode()))
  {
    return;
  }
  if (!this->GetScene())
  {
    vtkErrorMacro("CreateDefaultDisplayNodes: tool '" << (this->GetName() ? this->GetName() : "") << "' is not in a scene");
    return;
  }
  vtkMRMLVolumeCutToolDisplayNode* displayNode =
    vtkMRMLVolumeCutToolDisplayNode::SafeDownCast(this->GetScene()->AddNewNodeByClass("vtkMRMLVolumeCutToolDisplayNode"));
  if (!displayNode)
  {
    vtkErrorMacro("CreateDefaultDisplayNodes: vtkMRMLVolumeCutToolDisplayNode is not registered in the scene; "
                  "register it (vtkSlicerVolumeCuttingLogic does) before creating tools");
    return;
  }
  this->SetAndObserveDisplayNodeID(displayNode->GetID());
}

//----------------------------------------------------------------------------
vtkMRMLVolumeCutToolDisplayNode* vtkMRMLVolumeCutToolNode::GetVolumeCutToolDisplayNode()
{
  return vtkMRMLVolumeCutToolDisplayNode::SafeDownCast(this->GetDisplayNode());
}

//----------------------------------------------------------------------------
const char* vtkMRMLVolumeCutToolNode::GetShapeAsString(int shape)
{
  switch (shape)
  {
    case Sphere: return "Sphere";
    case Cylinder: return "Cylinder";
    case DiskSaw: return "DiskSaw";
    case Blade: return "Blade";
    case Mesh: return "Mesh";
    default: return nullptr;
  }
}

//----------------------------------------------------------------------------
int vtkMRMLVolumeCutToolNode::GetShapeFromString(const char* name)
{
  return EnumFromString(name, Shape_Last, &GetShapeAsString);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetShape(int shape)
{
  if (!GetShapeAsString(shape))
  {
    vtkErrorMacro("SetShape: " << shape << " is not a tool shape (Sphere " << Sphere << " to Mesh " << Mesh << "); the shape stays "
                               << GetShapeAsString(this->Shape));
    return;
  }
  if (shape == this->Shape)
  {
    return;
  }
  this->Shape = shape;
  this->Diameter = std::min(std::max(this->Diameter, GetMinimumDiameter(shape)), GetMaximumDiameter(shape));
  this->Modified();
  this->InvokeCustomModifiedEvent(ToolGeometryModifiedEvent);
}

//----------------------------------------------------------------------------
const char* vtkMRMLVolumeCutToolNode::GetBurrTypeAsString(int burrType)
{
  switch (burrType)
  {
    case Cutting: return "Cutting";
    case Diamond: return "Diamond";
    default: return nullptr;
  }
}

//----------------------------------------------------------------------------
int vtkMRMLVolumeCutToolNode::GetBurrTypeFromString(const char* name)
{
  return EnumFromString(name, BurrType_Last, &GetBurrTypeAsString);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetBurrType(int burrType)
{
  if (!GetBurrTypeAsString(burrType))
  {
    vtkErrorMacro("SetBurrType: " << burrType << " is not a burr type (Cutting " << Cutting << " or Diamond " << Diamond << "); the type stays "
                                  << GetBurrTypeAsString(this->BurrType));
    return;
  }
  if (burrType == this->BurrType)
  {
    return;
  }
  this->BurrType = burrType;
  this->Modified();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetValidatedValue(double& member, double value, double minimum, double maximum, const char* property, bool geometry)
{
  if (!std::isfinite(value) || value < minimum || value > maximum)
  {
    vtkErrorMacro("Set" << property << ": " << value << " is outside the valid range [" << minimum << ", " << maximum << "] of tool '"
                        << (this->GetName() ? this->GetName() : "") << "' (" << GetShapeAsString(this->Shape) << "); " << property
                        << " stays " << member);
    return;
  }
  if (value == member)
  {
    return;
  }
  member = value;
  this->Modified();
  if (geometry)
  {
    this->InvokeCustomModifiedEvent(ToolGeometryModifiedEvent);
  }
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMinimumDiameter(int shape)
{
  return shape == DiskSaw ? DiskSawDiameterRange[0] : BurrDiameterRange[0];
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMaximumDiameter(int shape)
{
  return shape == DiskSaw ? DiskSawDiameterRange[1] : BurrDiameterRange[1];
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetDiameter(double diameter)
{
  this->SetValidatedValue(this->Diameter, diameter, GetMinimumDiameter(this->Shape), GetMaximumDiameter(this->Shape), "Diameter", true);
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMinimumLength()
{
  return LengthRange[0];
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMaximumLength()
{
  return LengthRange[1];
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetLength(double length)
{
  this->SetValidatedValue(this->Length, length, LengthRange[0], LengthRange[1], "Length", true);
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMinimumThickness()
{
  return ThicknessRange[0];
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMaximumThickness()
{
  return ThicknessRange[1];
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetThickness(double thickness)
{
  this->SetValidatedValue(this->Thickness, thickness, ThicknessRange[0], ThicknessRange[1], "Thickness", true);
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMinimumWidth()
{
  return WidthRange[0];
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMaximumWidth()
{
  return WidthRange[1];
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetWidth(double width)
{
  this->SetValidatedValue(this->Width, width, WidthRange[0], WidthRange[1], "Width", true);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetPower(double power)
{
  this->SetValidatedValue(this->Power, power, 0.0, 1.0, "Power", false);
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetMaximumSpeed()
{
  return MaximumSpeed;
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetSpeed(double speed)
{
  this->SetValidatedValue(this->Speed, speed, 0.0, MaximumSpeed, "Speed", false);
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetCuttableSegmentIDs(const std::vector<std::string>& segmentIds)
{
  std::vector<std::string> unique;
  for (const std::string& id : segmentIds)
  {
    if (!id.empty() && !Contains(unique, id))
    {
      unique.push_back(id);
    }
  }
  if (unique == this->CuttableSegmentIDs)
  {
    return;
  }
  this->CuttableSegmentIDs = unique;
  this->Modified();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetSegmentCuttable(const std::string& segmentId, bool cuttable)
{
  std::vector<std::string> ids = this->CuttableSegmentIDs;
  if (cuttable)
  {
    ids.push_back(segmentId);
  }
  else
  {
    ids.erase(std::remove(ids.begin(), ids.end(), segmentId), ids.end());
  }
  this->SetCuttableSegmentIDs(ids);
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutToolNode::IsSegmentInCuttableList(const std::string& segmentId) const
{
  return Contains(this->CuttableSegmentIDs, segmentId);
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutToolNode::MayCutSegment(vtkMRMLVolumeCutNode* cutNode, const std::string& segmentId)
{
  if (cutNode && cutNode->IsSegmentProtected(segmentId))
  {
    return false;
  }
  if (this->UseCutNodeRoles)
  {
    return cutNode && cutNode->IsSegmentCuttable(segmentId);
  }
  return this->IsSegmentInCuttableList(segmentId);
}

//----------------------------------------------------------------------------
std::vector<std::string> vtkMRMLVolumeCutToolNode::GetEffectiveCuttableSegmentIDs(vtkMRMLVolumeCutNode* cutNode)
{
  if (this->UseCutNodeRoles)
  {
    return cutNode ? cutNode->GetCuttableSegmentIDs() : std::vector<std::string>();
  }
  // The own list may name segments the segmentation no longer has.
  vtkSegmentation* segmentation = cutNode && cutNode->GetSegmentationNode() ? cutNode->GetSegmentationNode()->GetSegmentation() : nullptr;
  std::vector<std::string> ids;
  for (const std::string& id : this->CuttableSegmentIDs)
  {
    if (this->MayCutSegment(cutNode, id) && (!segmentation || segmentation->GetSegment(id)))
    {
      ids.push_back(id);
    }
  }
  return ids;
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolNode::SetAndObserveMeshModelNodeID(const char* nodeId)
{
  this->SetAndObserveNodeReferenceID(MeshModelReferenceRole, nodeId);
}

//----------------------------------------------------------------------------
const char* vtkMRMLVolumeCutToolNode::GetMeshModelNodeID()
{
  return this->GetNodeReferenceID(MeshModelReferenceRole);
}

//----------------------------------------------------------------------------
vtkMRMLModelNode* vtkMRMLVolumeCutToolNode::GetMeshModelNode()
{
  return vtkMRMLModelNode::SafeDownCast(this->GetNodeReference(MeshModelReferenceRole));
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetCuttingRadius()
{
  switch (this->Shape)
  {
    case Sphere:
    case Cylinder:
    case DiskSaw: return 0.5 * this->Diameter;
    case Blade: return 0.5 * this->Width;
    default: return this->GetBoundingRadius();
  }
}

//----------------------------------------------------------------------------
double vtkMRMLVolumeCutToolNode::GetBoundingRadius()
{
  switch (this->Shape)
  {
    case Sphere: return 0.5 * this->Diameter;
    case Cylinder: return std::hypot(0.5 * this->Diameter, 0.5 * this->Length);
    case DiskSaw: return std::hypot(0.5 * this->Diameter, 0.5 * this->Thickness);
    case Blade: return 0.5 * std::sqrt(this->Width * this->Width + this->Thickness * this->Thickness + this->Length * this->Length);
    default: break;
  }
  vtkMRMLModelNode* model = this->GetMeshModelNode();
  vtkPointSet* mesh = model ? model->GetMesh() : nullptr;
  vtkPoints* points = mesh ? mesh->GetPoints() : nullptr;
  double radius = 0.0;
  for (vtkIdType i = 0; points && i < points->GetNumberOfPoints(); ++i)
  {
    double point[3];
    points->GetPoint(i, point);
    radius = std::max(radius, std::sqrt(point[0] * point[0] + point[1] * point[1] + point[2] * point[2]));
  }
  return radius;
}
