// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutField.h"

#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

#include <vtkIdList.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <vector>

namespace
{
const double Pi = vtkMath::Pi();

// Anatomy of 48^3 voxels, 0.5 mm, axis-aligned, origin at voxel (0,0,0).
void MakeGrid(vtkMatrix4x4* ijkToRas, double spacing = 0.5)
{
  ijkToRas->Identity();
  for (int axis = 0; axis < 3; ++axis)
  {
    ijkToRas->SetElement(axis, axis, spacing);
  }
}

// Oblique, anisotropic: rotated 25 degrees about an arbitrary axis, spacing 0.4 x 0.5 x 0.7 mm.
void MakeObliqueGrid(vtkMatrix4x4* ijkToRas)
{
  double axis[3] = { 1.0, 2.0, 0.5 };
  vtkMath::Normalize(axis);
  const double angle = vtkMath::RadiansFromDegrees(25.0);
  double quaternion[4] = { std::cos(angle / 2), axis[0] * std::sin(angle / 2), axis[1] * std::sin(angle / 2), axis[2] * std::sin(angle / 2) };
  double rotation[3][3];
  vtkMath::QuaternionToMatrix3x3(quaternion, rotation);
  const double spacing[3] = { 0.4, 0.5, 0.7 };
  ijkToRas->Identity();
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      ijkToRas->SetElement(row, column, rotation[row][column] * spacing[column]);
    }
  }
  ijkToRas->SetElement(0, 3, -3.0);
  ijkToRas->SetElement(1, 3, 2.0);
  ijkToRas->SetElement(2, 3, 1.0);
}

struct SurfaceError
{
  double Rms = 0.0;
  double Max = 0.0;
};

// Distance of the interpolated zero level from the exact sphere surface, at
// points of the exact surface (for a distance field, the value there is the
// offset of the reconstructed surface along the normal).
SurfaceError SphereSurfaceError(vtkVolumeCutField* field, const double center[3], double radius, double voxelSize)
{
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(7);
  SurfaceError error;
  const int samples = 4000;
  for (int n = 0; n < samples; ++n)
  {
    const double z = 2.0 * random->GetNextValue() - 1.0;
    const double phi = 2.0 * Pi * random->GetNextValue();
    const double r = std::sqrt(1.0 - z * z);
    const double p[3] = { center[0] + radius * r * std::cos(phi), center[1] + radius * r * std::sin(phi), center[2] + radius * z };
    const double offset = std::abs(field->GetSignedDistance(p)) / voxelSize;
    error.Rms += offset * offset;
    error.Max = std::max(error.Max, offset);
  }
  error.Rms = std::sqrt(error.Rms / samples);
  return error;
}

// Whole-voxel baseline (what open simulators do): a voxel is removed when its
// centre is inside the tool.
double WholeVoxelSphereVolume(vtkMatrix4x4* ijkToRas, const int dims[3], const double center[3], double radius)
{
  int count = 0;
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const double ijk[4] = { double(i), double(j), double(k), 1.0 };
        double ras[4];
        ijkToRas->MultiplyPoint(ijk, ras);
        count += vtkMath::Distance2BetweenPoints(ras, center) <= radius * radius;
      }
    }
  }
  return count * std::abs(ijkToRas->Determinant());
}

int TestSphereAccuracy(bool oblique)
{
  const int dims[3] = { 48, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  oblique ? MakeObliqueGrid(ijkToRas) : MakeGrid(ijkToRas);
  const double voxelSize = oblique ? 0.7 : 0.5; // the largest spacing: errors in voxels are then conservative
  double centerIjk[4] = { 23.37, 24.11, 22.83, 1.0 };
  double center[4];
  ijkToRas->MultiplyPoint(centerIjk, center);

  for (double radiusInVoxels : { 3.0, 5.0, 8.0 })
  {
    vtkNew<vtkVolumeCutField> sphereField;
    CHECK_BOOL(sphereField->Initialize(dims, ijkToRas, 2), true);
    const double radius = radiusInVoxels * 0.5;
    CHECK_BOOL(sphereField->CutCapsule(center, center, radius), true);
    const double exact = 4.0 / 3.0 * Pi * radius * radius * radius;
    const double volumeError = std::abs(sphereField->ComputeRemovedVolume() - exact) / exact;
    const double baselineError = std::abs(WholeVoxelSphereVolume(ijkToRas, dims, center, radius) - exact) / exact;
    const SurfaceError surface = SphereSurfaceError(sphereField, center, radius, voxelSize);
    std::cout << (oblique ? "oblique" : "axis-aligned") << " sphere r=" << radiusInVoxels << " voxels: volume error " << 100 * volumeError
              << " % (whole voxels " << 100 * baselineError << " %), surface RMS " << surface.Rms << " max " << surface.Max << " voxel" << std::endl;
    CHECK_BOOL(volumeError <= 0.005, true);
    CHECK_BOOL(surface.Rms <= 0.05, true);
    CHECK_BOOL(surface.Max <= 0.2, true);
  }
  return EXIT_SUCCESS;
}

int TestCapsuleAndStrokeEquivalence()
{
  const int dims[3] = { 64, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas);
  const double a[3] = { 5.1, 12.3, 11.7 };
  const double b[3] = { 26.9, 11.2, 12.9 };
  const double radius = 2.0;

  vtkNew<vtkVolumeCutField> oneStroke;
  oneStroke->Initialize(dims, ijkToRas, 2);
  CHECK_BOOL(oneStroke->CutCapsule(a, b, radius), true);
  const double length = std::sqrt(vtkMath::Distance2BetweenPoints(a, b));
  const double exact = Pi * radius * radius * length + 4.0 / 3.0 * Pi * radius * radius * radius;
  const double volumeError = std::abs(oneStroke->ComputeRemovedVolume() - exact) / exact;
  std::cout << "capsule: volume error " << 100 * volumeError << " %" << std::endl;
  CHECK_BOOL(volumeError <= 0.005, true);

  // 1000 small overlapping strokes along the same path, as a haptic device at
  // 1 kHz delivers them, in one undo step.
  vtkNew<vtkVolumeCutField> manyStrokes;
  manyStrokes->Initialize(dims, ijkToRas, 2);
  manyStrokes->BeginStroke();
  double previous[3] = { a[0], a[1], a[2] };
  for (int n = 1; n <= 1000; ++n)
  {
    const double t = n / 1000.0;
    const double next[3] = { a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2]) };
    CHECK_BOOL(manyStrokes->CutCapsule(previous, next, radius), true);
    std::copy(next, next + 3, previous);
  }
  manyStrokes->EndStroke();
  CHECK_INT(manyStrokes->GetNumberOfUndoSteps(), 1);

  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(3);
  double maximumDifference = 0.0;
  for (int n = 0; n < 20000; ++n)
  {
    const double p[3] = { a[0] - 3 + (b[0] - a[0] + 6) * random->GetNextValue(), 8.0 + 8.0 * random->GetNextValue(), 8.0 + 8.0 * random->GetNextValue() };
    maximumDifference = std::max(maximumDifference, std::abs(oneStroke->GetSignedDistance(p) - manyStrokes->GetSignedDistance(p)));
  }
  std::cout << "1000 strokes vs one: largest difference " << maximumDifference / 0.5 << " voxel" << std::endl;
  CHECK_BOOL(maximumDifference / 0.5 <= 0.02, true);
  return EXIT_SUCCESS;
}

// A drill path cut in segments: a segment after a restore or an undo cuts
// its whole reach, and segments remove what one capsule removes.
int TestSegmentedPathAfterRestoreAndUndo()
{
  const int dims[3] = { 64, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas);
  const double a[3] = { 6.0, 12.0, 12.0 };
  const double m[3] = { 14.0, 12.0, 12.0 };
  const double b[3] = { 22.0, 12.0, 12.0 };
  const double behind[3] = { 13.0, 12.0, 12.0 }; // inside the ball at m, behind m
  const double radius = 2.0;
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  CHECK_BOOL(field->CutCapsule(a, m, radius), true);
  CHECK_BOOL(field->RestoreCapsule(m, m, radius), true);
  CHECK_BOOL(field->GetSignedDistance(behind) > 0.0, true);
  CHECK_BOOL(field->CutCapsule(m, b, radius), true);
  CHECK_BOOL(field->GetSignedDistance(behind) < 0.0, true);

  // Undo between two segments likewise.
  vtkNew<vtkVolumeCutField> undone;
  undone->Initialize(dims, ijkToRas, 2);
  undone->CutCapsule(a, m, radius);
  undone->Undo();
  CHECK_BOOL(undone->CutCapsule(m, b, radius), true);
  CHECK_BOOL(undone->GetSignedDistance(behind) < 0.0, true);

  vtkNew<vtkVolumeCutField> continued;
  continued->Initialize(dims, ijkToRas, 2);
  continued->CutCapsule(a, m, radius);
  continued->CutCapsule(m, b, radius);
  vtkNew<vtkVolumeCutField> whole;
  whole->Initialize(dims, ijkToRas, 2);
  whole->CutCapsule(a, b, radius);
  CHECK_BOOL(std::abs(continued->ComputeRemovedVolume() - whole->ComputeRemovedVolume()) / whole->ComputeRemovedVolume() <= 1e-4, true);
  return EXIT_SUCCESS;
}


// Every stored sample is the exact clamped distance to the cut, on an oblique
// grid whose sizes are not whole bricks; samples of the last bricks that lie
// past the volume's far faces are never written.
int TestStoredDistancesAtTheFarFaces()
{
  const int dims[3] = { 21, 19, 17 }; // 42 x 38 x 34 sub-voxels: partial bricks on every far face
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeObliqueGrid(ijkToRas);
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);
  // A path ending beyond the far corner; its segments continue one another.
  double corner[3];
  const double farIndex[4] = { dims[0] - 1.0, dims[1] - 1.0, dims[2] - 1.0, 1.0 };
  double farRas[4];
  ijkToRas->MultiplyPoint(farIndex, farRas);
  std::copy(farRas, farRas + 3, corner);
  const double radius = 1.6;
  const double path[3][3] = { { corner[0] - 3.0, corner[1] - 2.0, corner[2] - 2.5 }, { corner[0] - 1.0, corner[1] - 0.5, corner[2] - 1.0 },
    { corner[0] + 1.0, corner[1] + 0.5, corner[2] + 0.5 } };
  CHECK_BOOL(field->CutCapsule(path[0], path[1], radius), true);
  CHECK_BOOL(field->CutCapsule(path[1], path[2], radius), true);

  vtkNew<vtkMatrix4x4> subToRas;
  field->GetSubVoxelIJKToRAS(subToRas);
  const int* subDims = field->GetDimensions();
  const int* brickDims = field->GetBrickDimensions();
  const double band = field->GetBandWidth();
  vtkNew<vtkIdList> bricks;
  field->GetBricksModifiedSince(0, bricks);
  CHECK_BOOL(bricks->GetNumberOfIds() > 0, true);
  bool reachedFarFace = false;
  double worst = 0.0;
  std::vector<short> values(vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize);
  for (vtkIdType n = 0; n < bricks->GetNumberOfIds(); ++n)
  {
    const vtkIdType id = bricks->GetId(n);
    const int b[3] = { static_cast<int>(id % brickDims[0]), static_cast<int>((id / brickDims[0]) % brickDims[1]),
      static_cast<int>(id / (static_cast<vtkIdType>(brickDims[0]) * brickDims[1])) };
    field->CopyBrick(id, values.data());
    for (int local = 0; local < static_cast<int>(values.size()); ++local)
    {
      const int s[3] = { b[0] * 8 + local % 8, b[1] * 8 + (local / 8) % 8, b[2] * 8 + local / 64 };
      if (s[0] >= subDims[0] || s[1] >= subDims[1] || s[2] >= subDims[2])
      {
        if (values[local] != std::numeric_limits<short>::max())
        {
          std::cerr << "sample " << s[0] << " " << s[1] << " " << s[2] << " past the volume was written" << std::endl;
          return EXIT_FAILURE;
        }
        continue;
      }
      const double index[4] = { double(s[0]), double(s[1]), double(s[2]), 1.0 };
      double ras[4];
      subToRas->MultiplyPoint(index, ras);
      double exact = band;
      for (int segment = 0; segment < 2; ++segment)
      {
        double ab[3];
        vtkMath::Subtract(path[segment + 1], path[segment], ab);
        double w[3];
        vtkMath::Subtract(ras, path[segment], w);
        const double t = std::min(1.0, std::max(0.0, vtkMath::Dot(w, ab) / vtkMath::Dot(ab, ab)));
        const double nearest[3] = { path[segment][0] + t * ab[0], path[segment][1] + t * ab[1], path[segment][2] + t * ab[2] };
        exact = std::min(exact, std::sqrt(vtkMath::Distance2BetweenPoints(ras, nearest)) - radius);
      }
      exact = std::max(-band, exact);
      worst = std::max(worst, std::abs(values[local] * field->GetQuantum() - exact));
      reachedFarFace |= (s[0] == subDims[0] - 1 || s[1] == subDims[1] - 1 || s[2] == subDims[2] - 1) && exact < 0.0;
    }
  }
  CHECK_BOOL(reachedFarFace, true);
  if (worst > 1e-4)
  {
    std::cerr << "stored distances differ from the exact ones by up to " << worst << " mm" << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

// Cuts skip bricks removed through and through, until a restore or an undo
// puts material back into them.
int TestFullyRemovedBricksReopen()
{
  const int dims[3] = { 48, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas);
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  const double center[3] = { 12.1, 12.3, 11.8 };
  CHECK_BOOL(field->CutCapsule(center, center, 5.0), true); // bricks at the centre are Inside throughout
  const double ball = field->ComputeRemovedVolume();
  CHECK_BOOL(field->RestoreCapsule(center, center, 2.0), true);
  CHECK_BOOL(field->GetSignedDistance(center) > 0.0, true);
  CHECK_BOOL(field->CutCapsule(center, center, 2.0), true);
  // Cut again, the ball is whole but for a seam of zero thickness where the
  // restore's surface was (the field touches 0 there without crossing it),
  // which the volume estimate counts as a sliver: 0.06 % here.
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), ball, 1e-3 * ball);
  CHECK_BOOL(field->GetSignedDistance(center) < 0.0, true);
  // Undo every step: the field is empty again, and a cut must cut.
  while (field->GetNumberOfUndoSteps() > 0)
  {
    CHECK_BOOL(field->Undo(), true);
  }
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), 0.0, 1e-12);
  CHECK_BOOL(field->CutCapsule(center, center, 2.0), true);
  CHECK_BOOL(field->GetSignedDistance(center) < 0.0, true);
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), 4.0 / 3.0 * Pi * 8.0, 0.005 * 4.0 / 3.0 * Pi * 8.0);
  return EXIT_SUCCESS;
}
//------------------------------------------------------------------------------
int TestRestoreUndoRedoAndStamps()
{
  const int dims[3] = { 48, 48, 48 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas);
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  const double center[3] = { 12.2, 11.9, 12.4 };
  const vtkTypeUInt64 start = field->GetCurrentStamp();
  CHECK_BOOL(field->CutCapsule(center, center, 4.0), true);
  const double bigVolume = field->ComputeRemovedVolume();

  vtkNew<vtkIdList> changed;
  field->GetBricksModifiedSince(start, changed);
  CHECK_INT(changed->GetNumberOfIds(), field->GetNumberOfAllocatedBricks());
  const vtkTypeUInt64 afterCut = field->GetCurrentStamp();

  // Restoring a concentric ball of radius 2 leaves a shell.
  CHECK_BOOL(field->RestoreCapsule(center, center, 2.0), true);
  const double shell = 4.0 / 3.0 * Pi * (64.0 - 8.0);
  const double shellVolume = field->ComputeRemovedVolume();
  CHECK_BOOL(std::abs(shellVolume - shell) / shell <= 0.005, true);
  CHECK_BOOL(field->GetSignedDistance(center) > 0.0, true);
  field->GetBricksModifiedSince(afterCut, changed);
  CHECK_BOOL(changed->GetNumberOfIds() > 0 && changed->GetNumberOfIds() < field->GetNumberOfAllocatedBricks(), true);

  CHECK_INT(field->GetNumberOfUndoSteps(), 2);
  CHECK_BOOL(field->Undo(), true);
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), bigVolume, 1e-9);
  CHECK_BOOL(field->Undo(), true);
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), 0.0, 1e-12);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(field->Undo(), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(field->Redo(), true);
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), bigVolume, 1e-9);
  CHECK_INT(field->GetNumberOfRedoSteps(), 1);
  // Back and forth: every state returns exactly (a step's after-state is
  // read back from the field when it is undone).
  for (int round = 0; round < 2; ++round)
  {
    CHECK_BOOL(field->Redo(), true);
    CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), shellVolume, 1e-12);
    CHECK_BOOL(field->GetSignedDistance(center) > 0.0, true);
    CHECK_BOOL(field->Undo(), true);
    CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), bigVolume, 1e-12);
    CHECK_BOOL(field->GetSignedDistance(center) < 0.0, true);
  }
  CHECK_INT(field->GetNumberOfRedoSteps(), 1);
  // A new stroke discards what could be redone.
  const double elsewhere[3] = { 5.0, 5.0, 5.0 };
  field->CutCapsule(elsewhere, elsewhere, 1.0);
  CHECK_INT(field->GetNumberOfRedoSteps(), 0);

  // A budget too small for the history drops the oldest steps, with a warning.
  const size_t used = field->GetUndoMemorySize();
  CHECK_BOOL(used > 0, true);
  field->SetUndoMemoryBudget(used);
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  const double another[3] = { 18.0, 5.0, 5.0 };
  field->CutCapsule(another, another, 1.0);
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  CHECK_BOOL(field->GetUndoMemorySize() <= field->GetUndoMemoryBudget(), true);
  return EXIT_SUCCESS;
}

int TestBadInputKeepsTheCut()
{
  const int dims[3] = { 32, 32, 32 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas);
  vtkNew<vtkVolumeCutField> field;
  const double p[3] = { 8.0, 8.0, 8.0 };

  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(field->CutCapsule(p, p, 1.0), false); // not initialized
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  const int badDims[3] = { 0, 32, 32 };
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(field->Initialize(badDims, ijkToRas, 2), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 3), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  vtkNew<vtkMatrix4x4> singular;
  singular->SetElement(2, 2, 0.0);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(field->Initialize(dims, singular, 2), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();

  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);
  CHECK_BOOL(field->CutCapsule(p, p, 2.0), true);
  const double volume = field->ComputeRemovedVolume();
  const vtkTypeUInt64 stamp = field->GetCurrentStamp();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const double nanPoint[3] = { nan, 1.0, 1.0 };
  const double infPoint[3] = { 1.0, inf, 1.0 };
  const double far[3] = { 8.0, 8.0, 120.0 };
  for (int attempt = 0; attempt < 5; ++attempt)
  {
    TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
    switch (attempt)
    {
      case 0: CHECK_BOOL(field->CutCapsule(nanPoint, p, 1.0), false); break;
      case 1: CHECK_BOOL(field->CutCapsule(p, infPoint, 1.0), false); break;
      case 2: CHECK_BOOL(field->CutCapsule(p, p, 0.0), false); break;
      case 3: CHECK_BOOL(field->CutCapsule(p, p, -1.0), false); break;
      default: CHECK_BOOL(field->CutCapsule(p, far, 1.0), false); break; // a jump across the volume
    }
    TESTING_OUTPUT_ASSERT_ERRORS_END();
  }
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), volume, 1e-12);
  CHECK_INT(static_cast<int>(field->GetCurrentStamp()), static_cast<int>(stamp));

  // Wholly outside the volume: a defined no-op.
  const double outside[3] = { -100.0, -100.0, -100.0 };
  CHECK_BOOL(field->CutCapsule(outside, outside, 2.0), true);
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), volume, 1e-12);
  return EXIT_SUCCESS;
}

int TestExportAndMemory()
{
  const int dims[3] = { 40, 40, 40 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas, 1.0);
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  const double center[3] = { 20.3, 19.6, 20.1 };
  field->CutCapsule(center, center, 6.0);
  vtkNew<vtkImageData> fraction;
  field->ExportRemovedFraction(fraction);
  CHECK_INT(fraction->GetDimensions()[0], 40);
  double sum = 0.0;
  for (vtkIdType n = 0; n < fraction->GetNumberOfPoints(); ++n)
  {
    sum += fraction->GetPointData()->GetScalars()->GetTuple1(n);
  }
  CHECK_DOUBLE_TOLERANCE(sum, field->ComputeRemovedVolume(), 1e-3 * sum);
  CHECK_DOUBLE_TOLERANCE(fraction->GetScalarComponentAsDouble(20, 20, 20, 0), 1.0, 1e-6);
  CHECK_DOUBLE_TOLERANCE(fraction->GetScalarComponentAsDouble(2, 2, 2, 0), 0.0, 1e-6);
  CHECK_BOOL(field->GetBrickMemorySize() < field->GetDenseMemorySize(), true);

  // The seqlock copy of a brick matches the samples the queries see.
  short values[vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize];
  vtkNew<vtkIdList> bricks;
  field->GetBricksModifiedSince(0, bricks);
  CHECK_BOOL(field->CopyBrick(bricks->GetId(0), values) > 0, true);
  return EXIT_SUCCESS;
}

// Protected voxels (a slab i >= 20, label 3) are never removed: a sphere
// centred on the slab's voxel face removes exactly a hemisphere, and the
// contact is reported with the structure's label and the tool's overlap.
int TestProtectedVoxelsAreNeverRemoved()
{
  const int dims[3] = { 40, 40, 40 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeGrid(ijkToRas);
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  vtkNew<vtkImageData> labels;
  labels->SetDimensions(dims[0], dims[1], dims[2]);
  labels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        labels->SetScalarComponentFromDouble(i, j, k, 0, i >= 20 ? 3 : 0);
      }
    }
  }
  CHECK_BOOL(field->SetProtectedLabels(labels), true);
  const double boundary = 19.5 * 0.5; // voxel face between i = 19 and i = 20
  const double center[3] = { boundary, 10.1, 9.8 };
  const double radius = 3.0;
  CHECK_BOOL(field->CutCapsule(center, center, radius), true);
  const double hemisphere = 2.0 / 3.0 * Pi * radius * radius * radius;
  const double error = std::abs(field->ComputeRemovedVolume() - hemisphere) / hemisphere;
  std::cout << "sphere on a protected face: removed volume error " << 100 * error << " % of a hemisphere" << std::endl;
  CHECK_BOOL(error < 0.005, true);
  const double inside[3] = { boundary + 0.05, 10.1, 9.8 };
  CHECK_BOOL(field->GetSignedDistance(inside) > 0.0, true);
  const double beside[3] = { boundary - 0.05, 10.1, 9.8 };
  CHECK_BOOL(field->GetSignedDistance(beside) < 0.0, true);
  CHECK_INT(field->GetContactLabel(), 3);
  CHECK_DOUBLE_TOLERANCE(field->GetMaximumContactDepth(), radius, 0.15);
  CHECK_BOOL(field->GetContactPosition()[0] > boundary, true);

  // Sweeping deep into the slab still leaves it whole.
  const double deep[3] = { boundary + 8.0, 10.1, 9.8 };
  field->CutCapsule(center, deep, radius);
  CHECK_BOOL(std::abs(field->ComputeRemovedVolume() - hemisphere) / hemisphere < 0.005, true);
  field->ResetContact();
  CHECK_INT(field->GetContactLabel(), 0);

  // Wrong dimensions are refused.
  vtkNew<vtkImageData> wrong;
  wrong->SetDimensions(10, 10, 10);
  wrong->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(field->SetProtectedLabels(wrong), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  return EXIT_SUCCESS;
}

// A cut is kept when the grid changes: resampled onto a finer sub-voxel
// factor and onto a cropped grid, the removed volume and the surface stay
// where they were.
int TestResampleKeepsTheCut()
{
  const int dims[3] = { 40, 40, 30 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  MakeObliqueGrid(ijkToRas);
  vtkNew<vtkVolumeCutField> field;
  field->Initialize(dims, ijkToRas, 2);
  double centerIndex[4] = { 20.0, 19.0, 14.0, 1.0 };
  double center[4];
  ijkToRas->MultiplyPoint(centerIndex, center);
  const double radius = 3.0;
  CHECK_BOOL(field->CutCapsule(center, center, radius), true);
  const double exact = 4.0 / 3.0 * Pi * radius * radius * radius;

  vtkNew<vtkVolumeCutField> finer;
  finer->Initialize(dims, ijkToRas, 4);
  CHECK_BOOL(finer->ResampleFrom(field), true);
  CHECK_INT(finer->GetNumberOfUndoSteps(), 0);
  const double finerError = std::abs(finer->ComputeRemovedVolume() - exact) / exact;
  const SurfaceError finerSurface = SphereSurfaceError(finer, center, radius, 0.4);

  // Cropped: 8 voxels fewer on each low side, the same physical voxels.
  const int croppedDims[3] = { 32, 32, 22 };
  vtkNew<vtkMatrix4x4> croppedToRas;
  croppedToRas->DeepCopy(ijkToRas);
  double shifted[4] = { 8.0, 8.0, 8.0, 1.0 };
  double origin[4];
  ijkToRas->MultiplyPoint(shifted, origin);
  for (int row = 0; row < 3; ++row)
  {
    croppedToRas->SetElement(row, 3, origin[row]);
  }
  vtkNew<vtkVolumeCutField> cropped;
  cropped->Initialize(croppedDims, croppedToRas, 2);
  CHECK_BOOL(cropped->ResampleFrom(field), true);
  const double croppedDifference = std::abs(cropped->ComputeRemovedVolume() - field->ComputeRemovedVolume());
  std::cout << "resampled cut: factor 2 -> 4 volume error " << 100 * finerError << " %, surface RMS " << finerSurface.Rms << " max " << finerSurface.Max
            << " voxel; cropped grid volume difference " << croppedDifference << " mm^3" << std::endl;
  CHECK_BOOL(finerError < 0.005, true);
  CHECK_BOOL(finerSurface.Max < 0.02, true);
  CHECK_BOOL(croppedDifference < 1e-6 * exact, true);

  vtkNew<vtkVolumeCutField> uninitialized;
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(uninitialized->ResampleFrom(field), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  return EXIT_SUCCESS;
}
} // namespace

int vtkVolumeCutFieldTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestSphereAccuracy(false));
  CHECK_EXIT_SUCCESS(TestSphereAccuracy(true));
  CHECK_EXIT_SUCCESS(TestCapsuleAndStrokeEquivalence());
  CHECK_EXIT_SUCCESS(TestSegmentedPathAfterRestoreAndUndo());
  CHECK_EXIT_SUCCESS(TestStoredDistancesAtTheFarFaces());
  CHECK_EXIT_SUCCESS(TestFullyRemovedBricksReopen());
  CHECK_EXIT_SUCCESS(TestRestoreUndoRedoAndStamps());
  CHECK_EXIT_SUCCESS(TestBadInputKeepsTheCut());
  CHECK_EXIT_SUCCESS(TestExportAndMemory());
  CHECK_EXIT_SUCCESS(TestProtectedVoxelsAreNeverRemoved());
  CHECK_EXIT_SUCCESS(TestResampleKeepsTheCut());
  return EXIT_SUCCESS;
}
