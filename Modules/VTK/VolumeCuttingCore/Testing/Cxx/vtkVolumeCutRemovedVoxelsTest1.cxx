// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutRemovedVoxels.h"

#include <vtkAddonTestingMacros.h>

#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <cmath>
#include <iostream>
#include <map>

namespace
{
std::map<vtkIdType, float> AsMap(vtkIdTypeArray* ids, vtkFloatArray* fractions)
{
  std::map<vtkIdType, float> voxels;
  for (vtkIdType n = 0; n < ids->GetNumberOfValues(); ++n)
  {
    voxels[ids->GetValue(n)] = fractions->GetValue(n);
  }
  return voxels;
}

// The tally updated stroke by stroke holds exactly what a full export of the
// field gives, through cuts, restores, undo, redo and a new shield, while
// recomputing only the bricks around each stroke.
int CheckAgainstFullExport(vtkVolumeCutRemovedVoxels* tally, vtkVolumeCutField* field, const char* when)
{
  tally->Update(field);
  vtkNew<vtkIdTypeArray> ids;
  vtkNew<vtkFloatArray> fractions;
  tally->GetVoxels(ids, fractions);
  vtkNew<vtkIdTypeArray> fullIds;
  vtkNew<vtkFloatArray> fullFractions;
  field->ExportRemovedVoxels(fullIds, fullFractions);
  if (AsMap(ids, fractions) != AsMap(fullIds, fullFractions))
  {
    std::cerr << "incremental tally differs from the full export " << when << std::endl;
    return EXIT_FAILURE;
  }
  const double voxelVolume = 0.5 * 0.5 * 0.75;
  CHECK_DOUBLE_TOLERANCE(tally->GetTotalFraction() * voxelVolume, field->ComputeRemovedVolume(), 1e-4 * (1.0 + field->ComputeRemovedVolume()));
  return EXIT_SUCCESS;
}
} // namespace

int vtkVolumeCutRemovedVoxelsTest1(int, char*[])
{
  const int dims[3] = { 64, 60, 40 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  ijkToRas->SetElement(0, 0, -0.5);
  ijkToRas->SetElement(1, 1, 0.5);
  ijkToRas->SetElement(2, 2, 0.75);
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);
  vtkNew<vtkVolumeCutRemovedVoxels> tally;
  CHECK_INT(static_cast<int>(tally->Update(field)), 0);

  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(5);
  auto point = [&](double* p) {
    p[0] = -(8.0 + 16.0 * random->GetNextValue());
    p[1] = 8.0 + 14.0 * random->GetNextValue();
    p[2] = 6.0 + 18.0 * random->GetNextValue();
  };
  vtkIdType lastRecomputed = 0;
  for (int stroke = 0; stroke < 12; ++stroke)
  {
    double p0[3];
    double p1[3];
    point(p0);
    for (int axis = 0; axis < 3; ++axis)
    {
      p1[axis] = p0[axis] + 3.0 * (random->GetNextValue() - 0.5);
    }
    if (stroke % 4 == 2)
    {
      field->RestoreCapsule(p0, p1, 1.5);
    }
    else
    {
      field->CutCapsule(p0, p1, 2.0);
    }
    lastRecomputed = tally->Update(field);
    if (stroke % 3 == 2)
    {
      CHECK_EXIT_SUCCESS(CheckAgainstFullExport(tally, field, "after a stroke"));
    }
  }
  const int* brickDims = field->GetBrickDimensions();
  std::cout << "a stroke recomputed " << lastRecomputed << " of " << field->GetNumberOfAllocatedBricks() << " allocated bricks ("
            << brickDims[0] * brickDims[1] * brickDims[2] << " in the field), tally " << tally->GetNumberOfVoxels() << " voxels" << std::endl;
  CHECK_BOOL(lastRecomputed < field->GetNumberOfAllocatedBricks(), true);

  CHECK_BOOL(field->Undo(), true);
  CHECK_EXIT_SUCCESS(CheckAgainstFullExport(tally, field, "after an undo"));
  CHECK_BOOL(field->Redo(), true);
  CHECK_EXIT_SUCCESS(CheckAgainstFullExport(tally, field, "after a redo"));
  CHECK_INT(static_cast<int>(tally->Update(field)), 0); // nothing changed since

  // A shield over part of the cut: voxels the field did not remove there drop out.
  vtkNew<vtkImageData> labels;
  labels->SetDimensions(dims[0], dims[1], dims[2]);
  labels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  labels->GetPointData()->GetScalars()->FillComponent(0, 0.0);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 30; i < 36; ++i)
      {
        labels->SetScalarComponentFromDouble(i, j, k, 0, 1);
      }
    }
  }
  CHECK_BOOL(field->SetProtectedLabels(labels), true);
  CHECK_EXIT_SUCCESS(CheckAgainstFullExport(tally, field, "after a new shield"));
  double p0[3] = { -15.0, 15.0, 15.0 };
  double p1[3] = { -19.0, 15.0, 15.0 };
  field->CutCapsule(p0, p1, 2.5);
  CHECK_EXIT_SUCCESS(CheckAgainstFullExport(tally, field, "after a stroke into the shield"));

  // The dense fraction and the drilled image hold the tally's voxels, nothing else.
  vtkNew<vtkIdTypeArray> ids;
  vtkNew<vtkFloatArray> fractions;
  tally->GetVoxels(ids, fractions);
  const std::map<vtkIdType, float> removed = AsMap(ids, fractions);
  vtkNew<vtkImageData> dense;
  tally->ExportFraction(dims, dense);
  CHECK_INT(static_cast<int>(dense->GetNumberOfPoints()), dims[0] * dims[1] * dims[2]);
  CHECK_STRING(dense->GetPointData()->GetScalars()->GetName(), "RemovedFraction");
  vtkNew<vtkImageData> drilled;
  drilled->SetDimensions(dims[0], dims[1], dims[2]);
  drilled->AllocateScalars(VTK_SHORT, 1);
  drilled->GetPointData()->GetScalars()->FillComponent(0, 100.0);
  tally->BlendTowards(drilled, -1000.0);
  vtkFloatArray* denseValues = vtkFloatArray::SafeDownCast(dense->GetPointData()->GetScalars());
  vtkDataArray* drilledValues = drilled->GetPointData()->GetScalars();
  int differing = 0;
  for (vtkIdType id = 0; id < dense->GetNumberOfPoints(); ++id)
  {
    auto found = removed.find(id);
    const float fraction = found != removed.end() ? found->second : 0.0f;
    const double blended = static_cast<short>(100.0 + fraction * (-1000.0 - 100.0));
    differing += denseValues->GetValue(id) != fraction || drilledValues->GetComponent(id, 0) != blended;
  }
  CHECK_INT(differing, 0);

  // Another field starts the tally over.
  vtkNew<vtkVolumeCutField> other;
  CHECK_BOOL(other->Initialize(dims, ijkToRas, 1), true);
  CHECK_EXIT_SUCCESS(CheckAgainstFullExport(tally, other, "for another field"));
  CHECK_INT(static_cast<int>(tally->GetNumberOfVoxels()), 0);
  return EXIT_SUCCESS;
}
