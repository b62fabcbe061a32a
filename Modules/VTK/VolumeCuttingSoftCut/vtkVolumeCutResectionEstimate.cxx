// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutResectionEstimate.h"
#include "vtkVolumeCutResectionPlanner.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataNormals.h"
#include "vtkTransform.h"
#include "vtkTransformPolyDataFilter.h"
#include "vtkWindowedSincPolyDataFilter.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutResectionEstimate);

namespace
{
/// Signed volume, area and volume centroid of a closed triangle mesh (divergence theorem).
void Measure(vtkPolyData* mesh, double& volume, double& area, double centroid[3])
{
  volume = 0.0;
  area = 0.0;
  double moment[3] = { 0.0, 0.0, 0.0 };
  vtkPoints* points = mesh->GetPoints();
  vtkCellArray* polys = mesh->GetPolys();
  if (!points || !polys)
  {
    std::fill(centroid, centroid + 3, 0.0);
    return;
  }
  const vtkIdType* ids;
  vtkIdType count;
  auto iterator = vtk::TakeSmartPointer(polys->NewIterator());
  for (iterator->GoToFirstCell(); !iterator->IsDoneWithTraversal(); iterator->GoToNextCell())
  {
    iterator->GetCurrentCell(count, ids);
    if (count != 3)
    {
      continue;
    }
    double p[3][3];
    for (int v = 0; v < 3; ++v)
    {
      points->GetPoint(ids[v], p[v]);
    }
    double cross[3];
    const double e1[3] = { p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2] };
    const double e2[3] = { p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2] };
    vtkMath::Cross(e1, e2, cross);
    area += 0.5 * vtkMath::Norm(cross);
    double c[3];
    vtkMath::Cross(p[1], p[2], c);
    const double tetra = vtkMath::Dot(p[0], c) / 6.0;
    volume += tetra;
    for (int a = 0; a < 3; ++a)
    {
      moment[a] += tetra * (p[0][a] + p[1][a] + p[2][a]) / 4.0;
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    centroid[a] = volume != 0.0 ? moment[a] / volume : 0.0;
  }
}
} // namespace

//------------------------------------------------------------------------------
vtkVolumeCutResectionEstimate::vtkVolumeCutResectionEstimate()
  : Surface(vtkSmartPointer<vtkPolyData>::New())
{
}

//------------------------------------------------------------------------------
vtkVolumeCutResectionEstimate::~vtkVolumeCutResectionEstimate() = default;

//------------------------------------------------------------------------------
void vtkVolumeCutResectionEstimate::SetPlanner(vtkVolumeCutResectionPlanner* planner)
{
  if (this->Planner != planner)
  {
    this->Planner = planner;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkVolumeCutResectionPlanner* vtkVolumeCutResectionEstimate::GetPlanner() const
{
  return this->Planner;
}

//------------------------------------------------------------------------------
vtkPolyData* vtkVolumeCutResectionEstimate::GetSurface() const
{
  return this->Surface;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionEstimate::GetFrameAxis(int axis, double direction[3]) const
{
  const int a = std::max(0, std::min(2, axis));
  std::copy(this->FrameAxes[a], this->FrameAxes[a] + 3, direction);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionEstimate::Update()
{
  this->ErrorMessage.clear();
  if (!this->Planner || !this->Planner->HasPlan())
  {
    this->ErrorMessage = "Update: there is no plan to measure; plan a resection first";
    vtkErrorMacro(<< this->ErrorMessage);
    return false;
  }
  vtkNew<vtkImageData> function;
  if (!this->Planner->BuildResectedTissueFunction(this->Depth, this->Subdivision, function))
  {
    this->ErrorMessage = std::string("Update: ") + this->Planner->GetErrorMessage();
    return false;
  }
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(function);
  contour->SetValue(0, 0.0);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  vtkNew<vtkMatrix4x4> ijkToRAS;
  this->Planner->GetIJKToRAS(ijkToRAS);
  vtkNew<vtkTransform> toRAS;
  toRAS->SetMatrix(ijkToRAS);
  vtkNew<vtkTransformPolyDataFilter> placed;
  placed->SetInputConnection(contour->GetOutputPort());
  placed->SetTransform(toRAS);
  placed->Update();
  vtkPolyData* raw = placed->GetOutput();
  double centroid[3];
  double area = 0.0;
  Measure(raw, this->ContourVolume, area, centroid);
  this->ContourVolume = std::abs(this->ContourVolume);

  vtkSmartPointer<vtkPolyData> smoothed = raw;
  if (this->SmoothingIterations > 0 && raw->GetNumberOfPoints() > 0)
  {
    vtkNew<vtkWindowedSincPolyDataFilter> smoother;
    smoother->SetInputData(raw);
    smoother->SetNumberOfIterations(this->SmoothingIterations);
    smoother->SetPassBand(this->PassBand);
    smoother->NormalizeCoordinatesOn();
    smoother->BoundarySmoothingOff();
    smoother->FeatureEdgeSmoothingOff();
    smoother->NonManifoldSmoothingOn();
    smoother->Update();
    smoothed = smoother->GetOutput();
  }
  // Outward normals: the triangles' winding made consistent and outward.
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(smoothed);
  normals->ConsistencyOn();
  normals->AutoOrientNormalsOn();
  normals->SplittingOff();
  normals->Update();
  this->Surface = vtkSmartPointer<vtkPolyData>::New();
  this->Surface->DeepCopy(normals->GetOutput());
  double volume = 0.0;
  Measure(this->Surface, volume, this->SurfaceArea, this->FrameOrigin);
  this->Volume = std::abs(volume);

  // The frame: thickness along the average normal, length and width along
  // the principal directions across it.
  double normal[3];
  this->Planner->GetAverageNormal(normal);
  double helper[3] = { 1.0, 0.0, 0.0 };
  if (std::abs(normal[0]) > 0.9)
  {
    helper[0] = 0.0;
    helper[1] = 1.0;
  }
  double u[3];
  double v[3];
  vtkMath::Cross(normal, helper, u);
  vtkMath::Normalize(u);
  vtkMath::Cross(normal, u, v);
  vtkPoints* points = this->Surface->GetPoints();
  const vtkIdType count = points ? points->GetNumberOfPoints() : 0;
  double suu = 0.0;
  double suv = 0.0;
  double svv = 0.0;
  for (vtkIdType id = 0; id < count; ++id)
  {
    double p[3];
    points->GetPoint(id, p);
    const double d[3] = { p[0] - this->FrameOrigin[0], p[1] - this->FrameOrigin[1], p[2] - this->FrameOrigin[2] };
    const double a = vtkMath::Dot(d, u);
    const double b = vtkMath::Dot(d, v);
    suu += a * a;
    suv += a * b;
    svv += b * b;
  }
  // The larger principal direction of the 2x2 covariance.
  const double angle = 0.5 * std::atan2(2.0 * suv, suu - svv);
  for (int a = 0; a < 3; ++a)
  {
    this->FrameAxes[0][a] = std::cos(angle) * u[a] + std::sin(angle) * v[a];
    this->FrameAxes[1][a] = -std::sin(angle) * u[a] + std::cos(angle) * v[a];
    this->FrameAxes[2][a] = normal[a];
  }
  double lower[3] = { 0.0, 0.0, 0.0 };
  double upper[3] = { 0.0, 0.0, 0.0 };
  for (vtkIdType id = 0; id < count; ++id)
  {
    double p[3];
    points->GetPoint(id, p);
    const double d[3] = { p[0] - this->FrameOrigin[0], p[1] - this->FrameOrigin[1], p[2] - this->FrameOrigin[2] };
    for (int a = 0; a < 3; ++a)
    {
      const double t = vtkMath::Dot(d, this->FrameAxes[a]);
      lower[a] = id == 0 ? t : std::min(lower[a], t);
      upper[a] = id == 0 ? t : std::max(upper[a], t);
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    this->Extents[a] = upper[a] - lower[a];
  }
  this->Modified();
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutResectionEstimate::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Depth: " << this->Depth << "\n";
  os << indent << "Subdivision: " << this->Subdivision << "\n";
  os << indent << "SmoothingIterations: " << this->SmoothingIterations << "\n";
  os << indent << "PassBand: " << this->PassBand << "\n";
  os << indent << "Volume: " << this->Volume << "\n";
  os << indent << "SurfaceArea: " << this->SurfaceArea << "\n";
  os << indent << "ContourVolume: " << this->ContourVolume << "\n";
  os << indent << "Extents: " << this->Extents[0] << " " << this->Extents[1] << " " << this->Extents[2] << "\n";
}
