// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The planner's inputs, Plan (growing the box until the resection fits) and
// the current plan's outputs; each step of the plan has its own file (see
// vtkVolumeCutResectionPlannerInternals.h).
#include "vtkVolumeCutResectionPlanner.h"
#include "vtkVolumeCutResectionPlannerInternals.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <cmath>

using namespace vtkVolumeCutSoftCut;

vtkStandardNewMacro(vtkVolumeCutResectionPlanner);

//------------------------------------------------------------------------------
vtkVolumeCutResectionPlanner::vtkVolumeCutResectionPlanner()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkVolumeCutResectionPlanner::~vtkVolumeCutResectionPlanner() = default;

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Fail(const std::string& message) const
{
  this->ErrorMessage = message;
  vtkErrorMacro(<< message);
  return false;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::SetAnatomy(vtkImageData* image, vtkMatrix4x4* ijkToRAS)
{
  this->Anatomy = image;
  if (ijkToRAS)
  {
    this->IJKToRAS = vtkSmartPointer<vtkMatrix4x4>::New();
    this->IJKToRAS->DeepCopy(ijkToRAS);
  }
  else if (image)
  {
    this->IJKToRAS = vtkSmartPointer<vtkMatrix4x4>::New();
    double origin[3];
    double spacing[3];
    image->GetOrigin(origin);
    image->GetSpacing(spacing);
    vtkMatrix3x3* direction = image->GetDirectionMatrix();
    for (int row = 0; row < 3; ++row)
    {
      for (int column = 0; column < 3; ++column)
      {
        this->IJKToRAS->SetElement(row, column, direction->GetElement(row, column) * spacing[column]);
      }
      this->IJKToRAS->SetElement(row, 3, origin[row]);
    }
  }
  else
  {
    this->IJKToRAS = nullptr;
  }
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::SetOutline(vtkPoints* points)
{
  this->Outline = vtkSmartPointer<vtkPoints>::New();
  if (points)
  {
    this->Outline->DeepCopy(points);
  }
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetIJKToRAS(vtkMatrix4x4* matrix) const
{
  if (matrix && this->IJKToRAS)
  {
    matrix->DeepCopy(this->IJKToRAS);
  }
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::Plan()
{
  // Each pass grows the faces of the box that the resection reached.
  for (int pass = 0; pass < 6; ++pass)
  {
    if (!this->BuildShape())
    {
      return false;
    }
    const bool* reached = this->Impl->Next->Reached;
    if (std::none_of(reached, reached + 6, [](bool r) { return r; }))
    {
      if (!this->BuildMask())
      {
        return false;
      }
      reached = this->Impl->Current->Reached;
      if (std::none_of(reached, reached + 6, [](bool r) { return r; }))
      {
        return true;
      }
    }
    for (int face = 0; face < 6; ++face)
    {
      if (reached[face])
      {
        const int axis = face / 2;
        this->Impl->Growth[face] += std::max(8, static_cast<int>(std::ceil(0.5 * this->MaximumDepth / this->Impl->Grid.Spacing[axis])));
      }
    }
  }
  vtkWarningMacro("Plan: the resection still reaches the bounding box after growing it six times; what lies beyond is left out");
  return !this->Impl->Next || this->BuildMask();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::UpdateGrid(const char* caller)
{
  Internals& impl = *this->Impl;
  const std::string where = std::string(caller) + ": ";
  vtkDataArray* scalars = this->Anatomy ? this->Anatomy->GetPointData()->GetScalars() : nullptr;
  if (!this->Anatomy || !this->IJKToRAS || !scalars)
  {
    return this->Fail(where + "no CT with scalars; give the planner the CT with SetAnatomy");
  }
  int dims[3];
  this->Anatomy->GetDimensions(dims);
  const int* extent = this->Anatomy->GetExtent();
  if (dims[0] < 2 || dims[1] < 2 || dims[2] < 2 || extent[0] != 0 || extent[2] != 0 || extent[4] != 0)
  {
    return this->Fail(where + "the CT must have at least 2 voxels along each axis and an extent starting at 0");
  }
  double spacing[3];
  double axes[3][3];
  for (int column = 0; column < 3; ++column)
  {
    Vec axis;
    for (int row = 0; row < 3; ++row)
    {
      axis[row] = this->IJKToRAS->GetElement(row, column);
    }
    spacing[column] = Norm(axis);
    if (!(spacing[column] > 0.0) || !std::isfinite(spacing[column]))
    {
      return this->Fail(where + "the CT's IJK-to-RAS matrix has a zero or non-finite spacing");
    }
    for (int row = 0; row < 3; ++row)
    {
      axes[row][column] = axis[row] / spacing[column];
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    for (int b = a + 1; b < 3; ++b)
    {
      if (std::abs(axes[0][a] * axes[0][b] + axes[1][a] * axes[1][b] + axes[2][a] * axes[2][b]) > 1e-3)
      {
        return this->Fail(where + "the CT's voxel axes are not orthogonal (a sheared grid); resample it onto an orthogonal grid first");
      }
    }
  }
  std::copy(dims, dims + 3, impl.Grid.Dims);
  std::copy(spacing, spacing + 3, impl.Grid.Spacing);
  for (int row = 0; row < 3; ++row)
  {
    std::copy(axes[row], axes[row] + 3, impl.Grid.Axes[row]);
    impl.Grid.Origin[row] = this->IJKToRAS->GetElement(row, 3);
  }
  // The local copy is made again for each outline (the CT may have changed).
  impl.Grid.ForgetCache();
  impl.Grid.Scalars = scalars;
  return true;
}

//------------------------------------------------------------------------------
double vtkVolumeCutResectionPlanner::GetDistanceToSkin(const double ras[3], double reach)
{
  if (!ras || !this->UpdateGrid("GetDistanceToSkin"))
  {
    return VTK_DOUBLE_MAX;
  }
  const Vec x = this->Impl->Grid.FromRAS({ ras[0], ras[1], ras[2] });
  Vec onSkin;
  if (!this->Impl->Grid.ToSkin(x, reach, this->SkinIsoValue, onSkin))
  {
    return VTK_DOUBLE_MAX;
  }
  return Norm(Sub(onSkin, x));
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::Internals::MakePolyline(const std::vector<Vec>& points, vtkPolyData* polyline) const
{
  vtkNew<vtkPoints> ras;
  vtkNew<vtkCellArray> lines;
  lines->InsertNextCell(static_cast<vtkIdType>(points.size()) + 1);
  for (const Vec& point : points)
  {
    const Vec r = this->Grid.ToRAS(point);
    lines->InsertCellPoint(ras->InsertNextPoint(r.data()));
  }
  lines->InsertCellPoint(0);
  polyline->SetPoints(ras);
  polyline->SetLines(lines);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::Internals::CopyPolyline(std::vector<Vec> PlanData::*which, vtkPolyData* polyline) const
{
  if (polyline)
  {
    polyline->Initialize();
    if (this->Current)
    {
      this->MakePolyline(this->Current.get()->*which, polyline);
    }
  }
}

//------------------------------------------------------------------------------
const vtkVolumeCutResectionPlanner::Internals::PlanData* vtkVolumeCutResectionPlanner::Internals::StartBoxImage(vtkImageData* image) const
{
  if (!image)
  {
    return nullptr;
  }
  image->Initialize();
  if (!this->Current)
  {
    return nullptr;
  }
  image->SetExtent(const_cast<int*>(this->Current->Box));
  return this->Current.get();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::HasPlan() const
{
  return this->Impl->Current != nullptr;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetBoxExtent(int extent[6]) const
{
  const PlanData* p = this->Impl->Current.get();
  for (int i = 0; i < 6; ++i)
  {
    extent[i] = p ? p->Box[i] : (i % 2 ? -1 : 0);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetOutlineOnSkin(vtkPolyData* polyline) const
{
  this->Impl->CopyPolyline(&PlanData::Points, polyline);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetInnerStrip(vtkPolyData* polyline) const
{
  this->Impl->CopyPolyline(&PlanData::Inner, polyline);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetOuterStrip(vtkPolyData* polyline) const
{
  this->Impl->CopyPolyline(&PlanData::Outer, polyline);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetAverageNormal(double normal[3]) const
{
  const Vec n = this->Impl->Current ? this->Impl->Grid.VectorToRAS(this->Impl->Current->AverageNormal) : Vec{ 0.0, 0.0, 0.0 };
  std::copy(n.begin(), n.end(), normal);
}

//------------------------------------------------------------------------------
double vtkVolumeCutResectionPlanner::GetOutlineLength() const
{
  return this->Impl->Current ? this->Impl->Current->Length : 0.0;
}

//------------------------------------------------------------------------------
double vtkVolumeCutResectionPlanner::GetProjectedArea() const
{
  return this->Impl->Current ? this->Impl->Current->Area : 0.0;
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutResectionPlanner::GetNumberOfFilledVoxels() const
{
  return this->Impl->Current ? this->Impl->Current->FilledCount : 0;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetShapeImage(vtkImageData* image) const
{
  const PlanData* p = this->Impl->StartBoxImage(image);
  if (!p)
  {
    return;
  }
  vtkNew<vtkUnsignedCharArray> classes;
  classes->SetName("Shape");
  classes->SetNumberOfTuples(p->Count);
  for (vtkIdType id = 0; id < p->Count; ++id)
  {
    classes->SetValue(id, p->Class[id] & (InShape | SkinPatch | FilledTissue));
  }
  image->GetPointData()->SetScalars(classes);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::GetDepthImage(vtkImageData* image) const
{
  const PlanData* p = this->Impl->StartBoxImage(image);
  if (!p)
  {
    return;
  }
  vtkNew<vtkFloatArray> depth;
  depth->SetName("Depth");
  depth->SetNumberOfTuples(p->Count);
  std::copy(p->Depth.begin(), p->Depth.end(), depth->GetPointer(0));
  image->GetPointData()->SetScalars(depth);
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionPlanner::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NormalMode: " << (this->NormalMode == LocalNormal ? "LocalNormal" : "AverageNormal") << "\n";
  os << indent << "SkinIsoValue: " << this->SkinIsoValue << "\n";
  os << indent << "SoftTissueRange: " << this->SoftTissueRange[0] << " " << this->SoftTissueRange[1] << "\n";
  os << indent << "StripOffset: " << this->StripOffset << "\n";
  os << indent << "MaximumDepth: " << this->MaximumDepth << "\n";
  os << indent << "SkinTolerance: " << this->SkinTolerance << "\n";
  os << indent << "Planned: " << (this->HasPlan() ? "yes" : "no") << "\n";
}

