// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutMaterialRemoval.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldDistanceSource.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkVolumeCutMaterialRemoval);

namespace
{
/// The burr's distance at the samples whose exposure reached what their
/// density requires, and "far" (no change) everywhere else.
class DepletedBurrSource : public vtkVolumeCutField::RowDistanceSource
{
public:
  using ExposureMap = std::unordered_map<vtkIdType, std::array<float, 512>>;

  DepletedBurrSource(const double center[3], const double axis[3], double radius, double dt, double far, const double rowStep[3],
    const double rasToIndex[4][4], const int brickDimensions[3], int factor, const int anatomyDimensions[3], vtkDataArray* hu,
    double secondsPerDensity, int burrType, double diamondEfficiency, ExposureMap& exposure)
    : Radius(radius)
    , Dt(dt)
    , Far(far)
    , Factor(factor)
    , Hu(hu)
    , SecondsPerDensity(secondsPerDensity)
    , BurrType(burrType)
    , DiamondEfficiency(diamondEfficiency)
    , Exposure(exposure)
  {
    const double norm = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    for (int c = 0; c < 3; ++c)
    {
      this->Center[c] = center[c];
      this->Axis[c] = axis[c] / norm;
      this->Step[c] = rowStep[c];
      this->BrickDimensions[c] = brickDimensions[c];
      this->AnatomyDimensions[c] = anatomyDimensions[c];
    }
    std::copy(&rasToIndex[0][0], &rasToIndex[0][0] + 16, &this->RASToIndex[0][0]);
  }

  void GetReachBounds(double lower[3], double upper[3]) const override
  {
    for (int c = 0; c < 3; ++c)
    {
      lower[c] = this->Center[c] - this->Radius;
      upper[c] = this->Center[c] + this->Radius;
    }
  }

  bool RowInterval(const double origin[3], double& first, double& last) const override
  {
    const double w[3] = { origin[0] - this->Center[0], origin[1] - this->Center[1], origin[2] - this->Center[2] };
    const double a = this->Step[0] * this->Step[0] + this->Step[1] * this->Step[1] + this->Step[2] * this->Step[2];
    const double b = 2.0 * (w[0] * this->Step[0] + w[1] * this->Step[1] + w[2] * this->Step[2]);
    const double c = w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - this->Radius * this->Radius;
    const double discriminant = b * b - 4.0 * a * c;
    if (discriminant < 0.0)
    {
      return false;
    }
    first = (-b - std::sqrt(discriminant)) / (2.0 * a);
    last = (-b + std::sqrt(discriminant)) / (2.0 * a);
    return true;
  }

  void RowDistances(const double origin[3], int first, int last, float* distances) const override
  {
    // Which row: the sub-voxel index of the row's origin.
    const int j = static_cast<int>(std::lround(this->RASToIndex[1][0] * origin[0] + this->RASToIndex[1][1] * origin[1] + this->RASToIndex[1][2] * origin[2] + this->RASToIndex[1][3]));
    const int k = static_cast<int>(std::lround(this->RASToIndex[2][0] * origin[0] + this->RASToIndex[2][1] * origin[1] + this->RASToIndex[2][2] * origin[2] + this->RASToIndex[2][3]));
    const int anatomyJ = std::min(this->AnatomyDimensions[1] - 1, std::max(0, static_cast<int>(std::lround((j + 0.5) / this->Factor - 0.5))));
    const int anatomyK = std::min(this->AnatomyDimensions[2] - 1, std::max(0, static_cast<int>(std::lround((k + 0.5) / this->Factor - 0.5))));
    for (int i = first; i <= last; ++i)
    {
      const double p[3] = { origin[0] + i * this->Step[0] - this->Center[0], origin[1] + i * this->Step[1] - this->Center[1],
        origin[2] + i * this->Step[2] - this->Center[2] };
      const double toolDistance = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - this->Radius;
      distances[i - first] = static_cast<float>(this->Far);
      if (toolDistance > 0.0)
      {
        continue;
      }
      const double along = p[0] * this->Axis[0] + p[1] * this->Axis[1] + p[2] * this->Axis[2];
      const double rho = std::sqrt(std::max(0.0, p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - along * along));
      const double radial = std::min(1.0, rho / this->Radius);
      const double power = this->BurrType == vtkVolumeCutMaterialRemoval::DiamondBurr ? this->DiamondEfficiency * (0.25 + 0.75 * radial) : radial;
      const vtkIdType brickId =
        (static_cast<vtkIdType>(k / 8) * this->BrickDimensions[1] + j / 8) * this->BrickDimensions[0] + i / 8;
      auto found = this->Exposure.find(brickId);
      if (found == this->Exposure.end())
      {
        found = this->Exposure.emplace(brickId, std::array<float, 512>{}).first;
      }
      float& exposure = found->second[((k % 8) * 8 + (j % 8)) * 8 + (i % 8)];
      exposure += static_cast<float>(power * this->Dt);
      const int anatomyI = std::min(this->AnatomyDimensions[0] - 1, std::max(0, static_cast<int>(std::lround((i + 0.5) / this->Factor - 0.5))));
      const double hu = this->Hu->GetComponent((static_cast<vtkIdType>(anatomyK) * this->AnatomyDimensions[1] + anatomyJ) * this->AnatomyDimensions[0] + anatomyI, 0);
      const double required = (std::max(hu, 0.0) / 1000.0 + 0.05) * this->SecondsPerDensity;
      if (exposure >= required)
      {
        distances[i - first] = static_cast<float>(toolDistance);
      }
    }
  }

  double Distance(const double point[3]) const override
  {
    const double p[3] = { point[0] - this->Center[0], point[1] - this->Center[1], point[2] - this->Center[2] };
    return std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - this->Radius;
  }

private:
  double Center[3];
  double Axis[3];
  double Step[3];
  double RASToIndex[4][4];
  int BrickDimensions[3];
  int AnatomyDimensions[3];
  double Radius;
  double Dt;
  double Far;
  int Factor;
  vtkDataArray* Hu;
  double SecondsPerDensity;
  int BurrType;
  double DiamondEfficiency;
  ExposureMap& Exposure;
};
} // namespace

//------------------------------------------------------------------------------
vtkVolumeCutMaterialRemoval::vtkVolumeCutMaterialRemoval() = default;

//------------------------------------------------------------------------------
vtkVolumeCutMaterialRemoval::~vtkVolumeCutMaterialRemoval()
{
  this->SetInputs(nullptr, nullptr);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutMaterialRemoval::SetInputs(vtkVolumeCutField* field, vtkImageData* hounsfieldUnits)
{
  this->Exposure.clear();
  if (this->Field)
  {
    this->Field->UnRegister(this);
    this->Field = nullptr;
  }
  if (this->HounsfieldUnits)
  {
    this->HounsfieldUnits->UnRegister(this);
    this->HounsfieldUnits = nullptr;
  }
  if (!field && !hounsfieldUnits)
  {
    return true;
  }
  if (!field || !hounsfieldUnits || !hounsfieldUnits->GetPointData()->GetScalars() || field->GetSubVoxelFactor() < 1)
  {
    vtkErrorMacro("SetInputs: an initialized cut field and a CT with voxel values are required");
    return false;
  }
  const int* dims = hounsfieldUnits->GetDimensions();
  const int f = field->GetSubVoxelFactor();
  for (int axis = 0; axis < 3; ++axis)
  {
    if (dims[axis] * f != field->GetDimensions()[axis])
    {
      vtkErrorMacro("SetInputs: the CT's dimensions differ from the cut field's anatomy");
      return false;
    }
  }
  this->Field = field;
  this->Field->Register(this);
  this->HounsfieldUnits = hounsfieldUnits;
  this->HounsfieldUnits->Register(this);
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutMaterialRemoval::SetInputsIfChanged(vtkVolumeCutField* field, vtkImageData* hounsfieldUnits)
{
  if (field && field == this->Field && hounsfieldUnits == this->HounsfieldUnits)
  {
    return true;
  }
  return this->SetInputs(field, hounsfieldUnits);
}

//------------------------------------------------------------------------------
void vtkVolumeCutMaterialRemoval::ResetExposure()
{
  this->Exposure.clear();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutMaterialRemoval::Drill(const double center[3], const double axis[3], double radius, double dt)
{
  if (!this->Field || !this->HounsfieldUnits)
  {
    vtkErrorMacro("Drill: no inputs");
    return false;
  }
  const double axisNorm = axis ? std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]) : 0.0;
  if (!center || !std::isfinite(center[0]) || !std::isfinite(center[1]) || !std::isfinite(center[2]) || !(axisNorm > 0.0) || !std::isfinite(axisNorm)
      || !(radius > 0.0) || !std::isfinite(radius) || !(dt > 0.0) || !std::isfinite(dt))
  {
    vtkErrorMacro("Drill: finite centre and axis, and positive radius and time step are required; nothing was removed");
    return false;
  }
  vtkVolumeCutField* field = this->Field;
  double spacing[3];
  field->GetSubVoxelSpacing(spacing);
  const double sampleSize = std::cbrt(spacing[0] * spacing[1] * spacing[2]);
  const double rowStep[3] = { field->SubIJKToRAS[0][0], field->SubIJKToRAS[1][0], field->SubIJKToRAS[2][0] };
  const int f = field->GetSubVoxelFactor();
  const int anatomyDimensions[3] = { field->Dimensions[0] / f, field->Dimensions[1] / f, field->Dimensions[2] / f };
  const DepletedBurrSource source(center, axis, radius, dt, field->GetBandWidth(), rowStep, field->RASToSubIJK, field->BrickDimensions, f,
    anatomyDimensions, this->HounsfieldUnits->GetPointData()->GetScalars(), sampleSize / this->RemovalRate, this->BurrType,
    this->DiamondEfficiency, this->Exposure);
  field->ApplyDistance(source, vtkVolumeCutField::Operation::Cut);
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutMaterialRemoval::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "BurrType: " << (this->BurrType == DiamondBurr ? "diamond" : "cutting") << "\n";
  os << indent << "RemovalRate: " << this->RemovalRate << " mm/s\n";
  os << indent << "DiamondEfficiency: " << this->DiamondEfficiency << "\n";
  os << indent << "ExposedBricks: " << this->Exposure.size() << "\n";
}
