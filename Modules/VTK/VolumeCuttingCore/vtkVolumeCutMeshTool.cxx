// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutMeshTool.h"

#include "vtkFeatureEdges.h"
#include "vtkImplicitPolyDataDistance.h"
#include "vtkObjectFactory.h"
#include "vtkPolyData.h"
#include "vtkTriangleFilter.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutMeshTool);

//------------------------------------------------------------------------------
vtkVolumeCutMeshTool::vtkVolumeCutMeshTool() = default;

//------------------------------------------------------------------------------
vtkVolumeCutMeshTool::~vtkVolumeCutMeshTool() = default;

//------------------------------------------------------------------------------
void vtkVolumeCutMeshTool::SetSurface(vtkPolyData* surface)
{
  this->Closed = false;
  this->NumberOfTriangles = 0;
  this->BoundingRadius = 0.0;
  if (!surface || surface->GetNumberOfPolys() == 0)
  {
    this->Modified();
    return;
  }
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputData(surface);
  triangles->Update();
  vtkPolyData* mesh = triangles->GetOutput();
  this->NumberOfTriangles = mesh->GetNumberOfPolys();

  vtkNew<vtkFeatureEdges> openEdges;
  openEdges->SetInputData(mesh);
  openEdges->BoundaryEdgesOn();
  openEdges->NonManifoldEdgesOn();
  openEdges->FeatureEdgesOff();
  openEdges->ManifoldEdgesOff();
  openEdges->Update();
  this->Closed = openEdges->GetOutput()->GetNumberOfCells() == 0;

  for (vtkIdType n = 0; n < mesh->GetNumberOfPoints(); ++n)
  {
    double point[3];
    mesh->GetPoint(n, point);
    this->BoundingRadius = std::max(this->BoundingRadius, std::sqrt(point[0] * point[0] + point[1] * point[1] + point[2] * point[2]));
  }
  this->Distance->SetInput(mesh);
  this->Modified();
}

//------------------------------------------------------------------------------
double vtkVolumeCutMeshTool::EvaluateDistance(const double local[3])
{
  return this->Distance->EvaluateFunction(const_cast<double*>(local));
}

//------------------------------------------------------------------------------
double vtkVolumeCutMeshTool::GetBoundingRadius()
{
  return this->BoundingRadius;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutMeshTool::IsValid()
{
  if (this->NumberOfTriangles == 0)
  {
    vtkErrorMacro("IsValid: the tool has no surface");
    return false;
  }
  if (!this->Closed)
  {
    vtkErrorMacro("IsValid: the tool's surface is not closed (it has boundary or non-manifold edges): its inside is undefined");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutMeshTool::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfTriangles: " << this->NumberOfTriangles << "\n";
  os << indent << "Closed: " << this->Closed << "\n";
  os << indent << "BoundingRadius: " << this->BoundingRadius << "\n";
}
