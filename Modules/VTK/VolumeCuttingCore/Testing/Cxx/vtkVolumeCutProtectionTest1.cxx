// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutProtection.h"
#include "vtkVolumeCutProtectionBrick.h" // the shield's samples, to compare them

#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <cmath>
#include <iostream>
#include <limits>

namespace
{
const double Pi = vtkMath::Pi();

// A flipped, anisotropic grid: x runs right to left, slices 3.5 times thicker.
void MakeFlippedAnisotropicGrid(vtkMatrix4x4* ijkToRas, const double spacing[3])
{
  ijkToRas->Identity();
  ijkToRas->SetElement(0, 0, -spacing[0]);
  ijkToRas->SetElement(1, 1, spacing[1]);
  ijkToRas->SetElement(2, 2, spacing[2]);
  ijkToRas->SetElement(0, 3, 20.0);
  ijkToRas->SetElement(1, 3, -7.0);
  ijkToRas->SetElement(2, 3, 3.0);
}

vtkSmartPointer<vtkImageData> MakeLabels(const int dims[3])
{
  auto labels = vtkSmartPointer<vtkImageData>::New();
  labels->SetDimensions(dims[0], dims[1], dims[2]);
  labels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  labels->GetPointData()->GetScalars()->FillComponent(0, 0.0);
  return labels;
}

// Exact distance (mm) from anatomy continuous index a to the union of the
// voxel cubes whose label satisfies wanted(label), by brute force.
template <typename Wanted>
double BruteForceDistance(vtkImageData* labels, const double a[3], const double spacing[3], Wanted wanted, int& nearestLabel)
{
  int dims[3];
  labels->GetDimensions(dims);
  double best = std::numeric_limits<double>::max();
  nearestLabel = 0;
  for (int k = -1; k <= dims[2]; ++k)
  {
    for (int j = -1; j <= dims[1]; ++j)
    {
      for (int i = -1; i <= dims[0]; ++i)
      {
        const bool inside = i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2];
        const int label = inside ? static_cast<int>(labels->GetScalarComponentAsDouble(i, j, k, 0)) : 0;
        if (!wanted(label))
        {
          continue;
        }
        const int c[3] = { i, j, k };
        double d2 = 0.0;
        for (int axis = 0; axis < 3; ++axis)
        {
          const double excess = std::max(0.0, std::abs(a[axis] - c[axis]) - 0.5) * spacing[axis];
          d2 += excess * excess;
        }
        if (d2 < best)
        {
          best = d2;
          nearestLabel = label;
        }
      }
    }
  }
  return std::sqrt(best);
}

// The shield of the voxel faces (no surface smoothing), built brick by
// brick, equals the brute-force distance to the shielded voxel cubes (within
// one quantum) at every sample of the bricks a tool reaches, on a flipped
// anisotropic grid, with two structures and a second label image; samples
// inside a structure carry its label.
int TestShieldMatchesBruteForce()
{
  const int dims[3] = { 24, 22, 10 };
  const double spacing[3] = { 0.7, 0.7, 2.5 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeFlippedAnisotropicGrid(ijkToRas, spacing);
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);

  // Image 0: a tube along z (value 4) and a block (value 7); image 1: a
  // shifted extent holding one blob (value 1).
  vtkSmartPointer<vtkImageData> first = MakeLabels(dims);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const double dx = (i - 8) * spacing[0];
        const double dy = (j - 9) * spacing[1];
        if (dx * dx + dy * dy <= 2.0 * 2.0)
        {
          first->SetScalarComponentFromDouble(i, j, k, 0, 4);
        }
        if (i >= 16 && i <= 19 && j >= 3 && j <= 6 && k >= 2 && k <= 5)
        {
          first->SetScalarComponentFromDouble(i, j, k, 0, 7);
        }
      }
    }
  }
  vtkNew<vtkImageData> second;
  second->SetExtent(14, 23, 12, 21, 4, 9);
  second->AllocateScalars(VTK_SHORT, 1);
  second->GetPointData()->GetScalars()->FillComponent(0, 0.0);
  for (int k = 6; k <= 7; ++k)
  {
    for (int j = 15; j <= 17; ++j)
    {
      for (int i = 17; i <= 19; ++i)
      {
        second->SetScalarComponentFromDouble(i, j, k, 0, 1);
      }
    }
  }
  vtkVolumeCutProtection* protection = field->GetProtection();
  protection->SetSurfaceSmoothing(0.0);
  const int firstIndex = protection->AddLabelImage(first);
  const int secondIndex = protection->AddLabelImage(second);
  CHECK_INT(firstIndex, 0);
  CHECK_INT(secondIndex, 1);
  CHECK_BOOL(protection->SetShieldLabel(firstIndex, 4, 2), true);
  CHECK_BOOL(protection->SetShieldLabel(firstIndex, 7, 3), true);
  CHECK_BOOL(protection->SetShieldLabel(secondIndex, 1, 5), true);
  CHECK_INT(protection->GetShieldLabel(8, 9, 0), 2);
  CHECK_INT(protection->GetShieldLabel(18, 16, 6), 5);
  CHECK_INT(protection->GetShieldLabel(0, 0, 0), 0);
  CHECK_INT(protection->GetShieldLabel(-1, 0, 0), 0);

  // The structures as one label image, for the brute force.
  vtkSmartPointer<vtkImageData> combined = MakeLabels(dims);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        combined->SetScalarComponentFromDouble(i, j, k, 0, protection->GetShieldLabel(i, j, k));
      }
    }
  }

  double sub[3];
  field->GetSubVoxelSpacing(sub);
  const double band = field->GetBandWidth();
  const int* brickDims = field->GetBrickDimensions();
  int compared = 0;
  double worst = 0.0;
  int labelMismatches = 0;
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(3);
  for (vtkIdType brickId = 0; brickId < static_cast<vtkIdType>(brickDims[0]) * brickDims[1] * brickDims[2]; ++brickId)
  {
    const vtkVolumeCutProtection::Brick* brick = protection->GetBrick(brickId);
    const int b[3] = { static_cast<int>(brickId % brickDims[0]), static_cast<int>((brickId / brickDims[0]) % brickDims[1]),
      static_cast<int>(brickId / (brickDims[0] * brickDims[1])) };
    for (int trial = 0; trial < 12; ++trial)
    {
      const int local = static_cast<int>(random->GetNextValue() * 512) % 512;
      const int s[3] = { b[0] * 8 + local % 8, b[1] * 8 + (local / 8) % 8, b[2] * 8 + local / 64 };
      if (s[0] >= dims[0] * 2 || s[1] >= dims[1] * 2 || s[2] >= dims[2] * 2)
      {
        continue;
      }
      double a[3];
      int own[3];
      for (int axis = 0; axis < 3; ++axis)
      {
        a[axis] = (s[axis] + 0.5) / 2.0 - 0.5;
        own[axis] = static_cast<int>(std::lround(a[axis]));
      }
      const int ownLabel = protection->GetShieldLabel(own[0], own[1], own[2]);
      int nearestLabel = 0;
      const double exact = ownLabel ? -BruteForceDistance(combined, a, spacing, [](int label) { return label == 0; }, nearestLabel)
                                    : BruteForceDistance(combined, a, spacing, [](int label) { return label != 0; }, nearestLabel);
      const double clamped = std::max(-band, std::min(band, exact));
      if (!brick)
      {
        // A free brick: nothing shielded within the band of any sample.
        CHECK_BOOL(clamped >= band - 1e-9, true);
        continue;
      }
      const double stored = brick->Distance[local] * field->GetQuantum();
      worst = std::max(worst, std::abs(stored - clamped));
      if (ownLabel)
      {
        labelMismatches += brick->Label[local] != ownLabel;
      }
      else if (exact < band - 1e-6)
      {
        // Ties between structures at the same distance may name either.
        int other = 0;
        const double toThat = BruteForceDistance(combined, a, spacing, [&](int label) { return label == brick->Label[local]; }, other);
        labelMismatches += std::abs(toThat - exact) > 1e-9;
      }
      ++compared;
    }
  }
  std::cout << "shield vs brute force: " << compared << " samples, max difference " << worst << " mm (quantum " << field->GetQuantum() << "), "
            << protection->GetNumberOfShieldBricks() << " of " << protection->GetNumberOfBuiltBricks() << " bricks hold a shield, "
            << protection->GetMemorySize() / 1024 << " KiB" << std::endl;
  CHECK_BOOL(compared > 500, true);
  CHECK_BOOL(worst <= field->GetQuantum(), true);
  CHECK_INT(labelMismatches, 0);

  // A role change forgets the bricks and costs no volume-sized work.
  CHECK_BOOL(protection->SetShieldLabel(firstIndex, 4, 0), true);
  CHECK_INT(protection->GetNumberOfBuiltBricks(), 0);
  CHECK_INT(protection->GetShieldLabel(8, 9, 0), 0);
  CHECK_BOOL(protection->HasShieldedLabels(), true);
  protection->RemoveAllShieldLabels();
  CHECK_BOOL(protection->HasShieldedLabels(), false);

  // Bad requests change nothing.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(protection->SetShieldLabel(5, 1, 1), false);
  CHECK_BOOL(protection->SetShieldLabel(0, 0, 1), false);
  CHECK_BOOL(protection->SetShieldLabel(0, 1, 256), false);
  vtkNew<vtkImageData> floating;
  floating->SetDimensions(2, 2, 2);
  floating->AllocateScalars(VTK_FLOAT, 1);
  CHECK_INT(protection->AddLabelImage(floating), -1);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_INT(protection->GetNumberOfLabelImages(), 2);
  return EXIT_SUCCESS;
}

// Shielded voxels report exactly zero removed fraction and volume where the
// field did not remove their inside, although the partial-volume ramp of the
// cut surface on their faces reaches into them; a cut made while a structure
// was cuttable still counts after it becomes shielded.
int TestShieldedVoxelsReportNothingRemoved()
{
  const int dims[3] = { 30, 30, 12 };
  const double spacing[3] = { 0.7, 0.7, 2.5 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeFlippedAnisotropicGrid(ijkToRas, spacing);
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);
  // A cord-like column i in [14, 17], j in [12, 17], all slices.
  vtkSmartPointer<vtkImageData> labels = MakeLabels(dims);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 12; j <= 17; ++j)
    {
      for (int i = 14; i <= 17; ++i)
      {
        labels->SetScalarComponentFromDouble(i, j, k, 0, 1);
      }
    }
  }
  CHECK_BOOL(field->SetProtectedLabels(labels), true);
  // A burr driven into the column's side from -j, off the voxel faces.
  double start[4] = { 15.5, 4.0, 5.3, 1.0 };
  double end[4] = { 15.5, 13.4, 5.3, 1.0 };
  double p0[4];
  double p1[4];
  ijkToRas->MultiplyPoint(start, p0);
  ijkToRas->MultiplyPoint(end, p1);
  CHECK_BOOL(field->CutCapsule(p0, p1, 1.75), true);
  CHECK_BOOL(field->GetMaximumContactDepth() > 0.5, true);
  CHECK_INT(field->GetContactLabel(), 1);

  vtkNew<vtkImageData> fraction;
  field->ExportRemovedFraction(fraction);
  double inColumn = 0.0;
  double beside = 0.0;
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const double value = fraction->GetScalarComponentAsDouble(i, j, k, 0);
        (labels->GetScalarComponentAsDouble(i, j, k, 0) > 0 ? inColumn : beside) += value;
      }
    }
  }
  std::cout << "burr against a shielded column: removed fraction inside " << inColumn << " voxels, beside " << beside << " voxels" << std::endl;
  CHECK_BOOL(inColumn == 0.0, true);
  CHECK_BOOL(beside > 10.0, true);
  const double voxelVolume = spacing[0] * spacing[1] * spacing[2];
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), beside * voxelVolume, 1e-3 * beside * voxelVolume);
  vtkNew<vtkIdTypeArray> ids;
  vtkNew<vtkFloatArray> values;
  field->ExportRemovedVoxels(ids, values);
  double sparse = 0.0;
  for (vtkIdType n = 0; n < ids->GetNumberOfValues(); ++n)
  {
    const vtkIdType id = ids->GetValue(n);
    CHECK_BOOL(labels->GetPointData()->GetScalars()->GetComponent(id, 0) == 0, true);
    CHECK_BOOL(values->GetValue(n) > 0.0f, true);
    sparse += values->GetValue(n);
  }
  CHECK_DOUBLE_TOLERANCE(sparse, beside, 1e-3);

  // Without the shield the same column is cut: what was removed there counts
  // when it is shielded later, and the spill of a face is never counted.
  field->SetProtectedLabels(nullptr);
  double deeper[4] = { 15.5, 15.0, 5.3, 1.0 };
  double p2[4];
  ijkToRas->MultiplyPoint(deeper, p2);
  CHECK_BOOL(field->CutCapsule(p1, p2, 1.75), true);
  CHECK_BOOL(field->SetProtectedLabels(labels), true);
  field->ExportRemovedFraction(fraction);
  inColumn = 0.0;
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        if (labels->GetScalarComponentAsDouble(i, j, k, 0) > 0)
        {
          inColumn += fraction->GetScalarComponentAsDouble(i, j, k, 0);
        }
      }
    }
  }
  std::cout << "column cut before it was shielded: " << inColumn << " voxels removed inside" << std::endl;
  CHECK_BOOL(inColumn > 5.0, true);
  return EXIT_SUCCESS;
}

// The first stroke near long shielded structures builds only the bricks it
// reaches: a patient-scale grid, two tubes through all slices.
int TestShieldIsBuiltWhereToolsReach()
{
  const int dims[3] = { 256, 256, 133 };
  const double spacing[3] = { 0.7, 0.7, 2.5 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeFlippedAnisotropicGrid(ijkToRas, spacing);
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);
  vtkSmartPointer<vtkImageData> labels = MakeLabels(dims);
  unsigned char* voxels = static_cast<unsigned char*>(labels->GetScalarPointer());
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const double cord = std::hypot((i - 128) * spacing[0], (j - 150) * spacing[1]);
        const double vessel = std::hypot((i - 100 - 20 * std::sin(k * 0.05)) * spacing[0], (j - 110) * spacing[1]);
        voxels[(static_cast<size_t>(k) * dims[1] + j) * dims[0] + i] = cord <= 5.0 ? 1 : vessel <= 10.0 ? 2 : 0;
      }
    }
  }
  CHECK_BOOL(field->SetProtectedLabels(labels), true);
  CHECK_INT(field->GetProtection()->GetNumberOfBuiltBricks(), 0);
  double a[4] = { 128.0, 135.0, 60.0, 1.0 };
  double b[4] = { 128.0, 141.0, 60.0, 1.0 };
  double p0[4];
  double p1[4];
  ijkToRas->MultiplyPoint(a, p0);
  ijkToRas->MultiplyPoint(b, p1);
  CHECK_BOOL(field->CutCapsule(p0, p1, 1.75), true);
  const vtkIdType built = field->GetProtection()->GetNumberOfBuiltBricks();
  std::cout << "first stroke beside the cord built " << built << " shield bricks ("
            << field->GetProtection()->GetNumberOfShieldBricks() << " near a structure) of "
            << field->GetBrickDimensions()[0] * field->GetBrickDimensions()[1] * field->GetBrickDimensions()[2] << std::endl;
  CHECK_BOOL(built > 0 && built < 200, true);
  CHECK_BOOL(field->GetMaximumContactDepth() > 0.0, true);
  CHECK_INT(field->GetContactLabel(), 1);
  return EXIT_SUCCESS;
}
} // namespace

int vtkVolumeCutProtectionTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestShieldMatchesBruteForce());
  CHECK_EXIT_SUCCESS(TestShieldedVoxelsReportNothingRemoved());
  CHECK_EXIT_SUCCESS(TestShieldIsBuiltWhereToolsReach());
  return EXIT_SUCCESS;
}
