// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutRemovedVoxels.h"
#include "vtkVolumeCutField.h"

#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"

#include <unordered_set>

vtkStandardNewMacro(vtkVolumeCutRemovedVoxels);

//------------------------------------------------------------------------------
vtkVolumeCutRemovedVoxels::vtkVolumeCutRemovedVoxels() = default;

//------------------------------------------------------------------------------
vtkVolumeCutRemovedVoxels::~vtkVolumeCutRemovedVoxels() = default;

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutRemovedVoxels::Update(vtkVolumeCutField* field)
{
  if (!field)
  {
    this->Bricks.clear();
    this->Field = nullptr;
    return 0;
  }
  // The stamp first: a brick written while this runs is recomputed next time.
  const vtkTypeUInt64 stamp = field->GetCurrentStamp();
  const vtkMTimeType shieldTime = field->GetProtection()->GetMTime();
  vtkNew<vtkIdList> changed;
  const bool restart = this->Field != field || this->ShieldTime != shieldTime;
  if (restart)
  {
    this->Bricks.clear();
    this->Field = field;
    this->ShieldTime = shieldTime;
    field->GetBricksModifiedSince(0, changed);
  }
  else
  {
    field->GetBricksModifiedSince(this->Stamp, changed);
  }
  this->Stamp = stamp;
  const int* dims = field->GetBrickDimensions();
  std::unordered_set<vtkIdType> recompute;
  for (vtkIdType n = 0; n < changed->GetNumberOfIds(); ++n)
  {
    const vtkIdType id = changed->GetId(n);
    const int b[3] = { static_cast<int>(id % dims[0]), static_cast<int>((id / dims[0]) % dims[1]), static_cast<int>(id / (static_cast<vtkIdType>(dims[0]) * dims[1])) };
    for (int dk = -1; dk <= 1; ++dk)
    {
      for (int dj = -1; dj <= 1; ++dj)
      {
        for (int di = -1; di <= 1; ++di)
        {
          const int c[3] = { b[0] + di, b[1] + dj, b[2] + dk };
          if (c[0] >= 0 && c[1] >= 0 && c[2] >= 0 && c[0] < dims[0] && c[1] < dims[1] && c[2] < dims[2])
          {
            recompute.insert((static_cast<vtkIdType>(c[2]) * dims[1] + c[1]) * dims[0] + c[0]);
          }
        }
      }
    }
  }
  for (vtkIdType id : recompute)
  {
    this->Recompute(id);
  }
  if (restart || !recompute.empty())
  {
    this->Modified();
  }
  return static_cast<vtkIdType>(recompute.size());
}

//------------------------------------------------------------------------------
void vtkVolumeCutRemovedVoxels::Recompute(vtkIdType brickId)
{
  vtkNew<vtkIdTypeArray> ids;
  vtkNew<vtkFloatArray> fractions;
  this->Field->AppendRemovedVoxelsOfBrick(brickId, ids, fractions);
  if (ids->GetNumberOfValues() == 0)
  {
    this->Bricks.erase(brickId);
    return;
  }
  std::vector<std::pair<vtkIdType, float>>& voxels = this->Bricks[brickId];
  voxels.resize(static_cast<size_t>(ids->GetNumberOfValues()));
  for (vtkIdType n = 0; n < ids->GetNumberOfValues(); ++n)
  {
    voxels[n] = { ids->GetValue(n), fractions->GetValue(n) };
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutRemovedVoxels::GetVoxels(vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const
{
  if (!anatomyVoxelIds || !fractions)
  {
    return;
  }
  anatomyVoxelIds->Reset();
  fractions->Reset();
  fractions->SetName("RemovedFraction");
  anatomyVoxelIds->Allocate(this->GetNumberOfVoxels());
  fractions->Allocate(this->GetNumberOfVoxels());
  this->ForEachVoxel([&](vtkIdType id, float fraction) {
    anatomyVoxelIds->InsertNextValue(id);
    fractions->InsertNextValue(fraction);
  });
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutRemovedVoxels::GetNumberOfVoxels() const
{
  vtkIdType count = 0;
  for (const auto& brick : this->Bricks)
  {
    count += static_cast<vtkIdType>(brick.second.size());
  }
  return count;
}

//------------------------------------------------------------------------------
double vtkVolumeCutRemovedVoxels::GetTotalFraction() const
{
  double total = 0.0;
  this->ForEachVoxel([&](vtkIdType, float fraction) { total += fraction; });
  return total;
}

//------------------------------------------------------------------------------
void vtkVolumeCutRemovedVoxels::ExportFraction(const int anatomyDimensions[3], vtkImageData* fraction) const
{
  if (!fraction)
  {
    return;
  }
  fraction->SetDimensions(anatomyDimensions[0], anatomyDimensions[1], anatomyDimensions[2]);
  fraction->AllocateScalars(VTK_FLOAT, 1);
  vtkFloatArray* scalars = vtkFloatArray::SafeDownCast(fraction->GetPointData()->GetScalars());
  scalars->SetName("RemovedFraction");
  scalars->FillValue(0.0f);
  float* values = scalars->GetPointer(0);
  this->ForEachVoxel([values](vtkIdType id, float removed) { values[id] = removed; });
}

//------------------------------------------------------------------------------
void vtkVolumeCutRemovedVoxels::BlendTowards(vtkImageData* anatomy, double fillValue) const
{
  vtkDataArray* voxels = anatomy ? anatomy->GetPointData()->GetScalars() : nullptr;
  if (!voxels)
  {
    return;
  }
  const vtkIdType voxelCount = anatomy->GetNumberOfPoints();
  this->ForEachVoxel([&](vtkIdType id, float removed) {
    if (removed > 0.0f && id < voxelCount)
    {
      const double value = voxels->GetComponent(id, 0);
      voxels->SetComponent(id, 0, value + removed * (fillValue - value));
    }
  });
}

//------------------------------------------------------------------------------
void vtkVolumeCutRemovedVoxels::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Bricks: " << this->Bricks.size() << "\n";
  os << indent << "Voxels: " << this->GetNumberOfVoxels() << "\n";
  os << indent << "Stamp: " << this->Stamp << "\n";
}
