// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutResectionEstimate.h"
#include "vtkVolumeCutResectionPlanner.h"

#include "vtkVolumeCutField.h"

#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <cmath>
#include <string>

namespace
{
// A head-like sphere: skin of radius 30 mm, soft tissue down to a bone shell
// (24 to 21 mm), brain inside; voxels 1 x 1 x 1.25 mm, the grid's i axis
// flipped (i runs towards patient right, as in many CTs).
const double SkinRadius = 30.0;
const double BoneOuter = 24.0;
const double BoneInner = 21.0;
const double Air = -1000.0;
const double Tissue = 40.0;
const double Bone = 1200.0;
const double Iso = 0.5 * (Air + Tissue);
const double BoneThreshold = 0.5 * (Tissue + Bone);
const int Dims[3] = { 72, 72, 58 };
const double Spacing[3] = { 1.0, 1.0, 1.25 };
const double Pi = 3.14159265358979323846;

double Step(double x)
{
  return 0.5 * (1.0 + std::tanh(x / 0.75));
}

void IJKToRAS(vtkMatrix4x4* matrix)
{
  matrix->Identity();
  matrix->SetElement(0, 0, -Spacing[0]);
  matrix->SetElement(1, 1, Spacing[1]);
  matrix->SetElement(2, 2, Spacing[2]);
  // The sphere's centre at RAS 0, the grid's centre.
  matrix->SetElement(0, 3, Spacing[0] * (Dims[0] - 1) / 2.0);
  matrix->SetElement(1, 3, -Spacing[1] * (Dims[1] - 1) / 2.0);
  matrix->SetElement(2, 3, -Spacing[2] * (Dims[2] - 1) / 2.0);
}

void MakeCT(vtkImageData* ct, vtkMatrix4x4* ijkToRAS, bool boneSkin = false)
{
  ct->SetDimensions(Dims[0], Dims[1], Dims[2]);
  ct->AllocateScalars(VTK_FLOAT, 1);
  float* values = static_cast<float*>(ct->GetScalarPointer());
  for (int k = 0; k < Dims[2]; ++k)
  {
    for (int j = 0; j < Dims[1]; ++j)
    {
      for (int i = 0; i < Dims[0]; ++i)
      {
        const double ijk[4] = { double(i), double(j), double(k), 1.0 };
        double ras[4];
        ijkToRAS->MultiplyPoint(ijk, ras);
        const double r = std::sqrt(ras[0] * ras[0] + ras[1] * ras[1] + ras[2] * ras[2]);
        double value;
        if (boneSkin)
        {
          // Bone right under the air: nothing soft to resect.
          value = Air + (Bone - Air) * Step(SkinRadius - r);
        }
        else
        {
          value = Air + (Tissue - Air) * Step(SkinRadius - r) + (Bone - Tissue) * (Step(BoneOuter - r) - Step(BoneInner - r));
        }
        values[(k * Dims[1] + j) * Dims[0] + i] = static_cast<float>(value);
      }
    }
  }
}

/// Points on the skin around the top (+S) at distance radius from the axis.
void Circle(double radius, int count, vtkPoints* points, bool figureEight = false)
{
  points->Reset();
  const double height = std::sqrt(SkinRadius * SkinRadius - radius * radius);
  for (int n = 0; n < count; ++n)
  {
    const double a = 2.0 * Pi * n / count;
    // A figure eight crosses itself at the pole.
    const double x = figureEight ? radius * std::sin(2.0 * a) / 2.0 : radius * std::cos(a);
    const double y = radius * std::sin(a);
    const double z = std::sqrt(SkinRadius * SkinRadius - x * x - y * y);
    points->InsertNextPoint(x, y, figureEight ? z : height);
  }
}

double ExactLocalNormalVolume(double radius, double depth)
{
  const double theta = std::asin(radius / SkinRadius);
  const double inner = std::max(SkinRadius - depth, BoneOuter);
  return 2.0 * Pi / 3.0 * (1.0 - std::cos(theta)) * (std::pow(SkinRadius, 3) - std::pow(inner, 3));
}

bool Fails(vtkVolumeCutResectionPlanner* planner, const std::string& expected)
{
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  const bool planned = planner->Plan();
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  if (planned || std::string(planner->GetErrorMessage()).find(expected) == std::string::npos)
  {
    std::cerr << "expected a failure mentioning '" << expected << "', got " << (planned ? "success" : planner->GetErrorMessage()) << std::endl;
    return false;
  }
  return true;
}
} // namespace

int vtkVolumeCutResectionPlannerTest1(int, char*[])
{
  vtkNew<vtkMatrix4x4> ijkToRAS;
  IJKToRAS(ijkToRAS);
  vtkNew<vtkImageData> ct;
  MakeCT(ct, ijkToRAS);
  vtkNew<vtkVolumeCutResectionPlanner> planner;
  planner->SetAnatomy(ct, ijkToRAS);
  planner->SetSkinIsoValue(Iso);
  planner->SetSoftTissueRange(Iso, BoneThreshold);
  planner->SetMaximumDepth(12.0);
  vtkNew<vtkPoints> outline;
  const double radius = 10.0;
  Circle(radius, 240, outline);
  planner->SetOutline(outline);
  CHECK_BOOL(planner->Plan(), true);
  CHECK_BOOL(planner->HasPlan(), true);
  CHECK_BOOL(planner->GetNumberOfFilledVoxels() > 0, true);
  CHECK_DOUBLE_TOLERANCE(planner->GetOutlineLength(), 2.0 * Pi * radius, 0.02 * 2.0 * Pi * radius);
  double normal[3];
  planner->GetAverageNormal(normal);
  CHECK_DOUBLE_TOLERANCE(normal[2], 1.0, 1e-3);
  vtkNew<vtkPolyData> inner;
  vtkNew<vtkPolyData> outer;
  planner->GetInnerStrip(inner);
  planner->GetOuterStrip(outer);
  double innerPoint[3];
  double outerPoint[3];
  inner->GetPoint(0, innerPoint);
  outer->GetPoint(0, outerPoint);
  // The inner strip lies inside the outline, the outer one outside.
  CHECK_BOOL(std::hypot(innerPoint[0], innerPoint[1]) < radius && std::hypot(outerPoint[0], outerPoint[1]) > radius, true);

  // Resected volume against the exact spherical sector's shell, above and below the bone.
  vtkNew<vtkVolumeCutResectionEstimate> estimate;
  estimate->SetPlanner(planner);
  for (double depth : { 4.0, 10.0 })
  {
    estimate->SetDepth(depth);
    CHECK_BOOL(estimate->Update(), true);
    const double exact = ExactLocalNormalVolume(radius, depth);
    if (std::abs(estimate->GetVolume() / exact - 1.0) > 0.02)
    {
      std::cerr << "depth " << depth << ": resected volume " << estimate->GetVolume() << " mm^3, exact " << exact << std::endl;
      return EXIT_FAILURE;
    }
    CHECK_DOUBLE_TOLERANCE(estimate->GetExtents()[0], 2.0 * radius, 1.0);
    CHECK_BOOL(estimate->GetSurfaceArea() > 0.0 && estimate->GetSurface()->GetNumberOfPolys() > 0, true);
  }

  // Carving: one undo step, bone never removed, about the tissue expected.
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(Dims, ijkToRAS, 2), true);
  CHECK_BOOL(planner->Carve(field, 10.0), true);
  CHECK_INT(field->GetNumberOfUndoSteps(), 1);
  vtkNew<vtkImageData> removed;
  field->ExportRemovedFraction(removed);
  const float* fraction = static_cast<float*>(removed->GetScalarPointer());
  const float* values = static_cast<float*>(ct->GetScalarPointer());
  double tissueRemoved = 0.0;
  for (vtkIdType id = 0; id < ct->GetNumberOfPoints(); ++id)
  {
    if (values[id] > BoneThreshold && fraction[id] > 0.0f)
    {
      // Bone through and through (the voxel and its 26 neighbours above the
      // soft-tissue range) loses nothing; a voxel of the bone's surface, a
      // mixture, at most its soft-tissue part (the analytic shell's
      // complement in its cube, 4^3 points).
      const int ijk[3] = { int(id % Dims[0]), int((id / Dims[0]) % Dims[1]), int(id / (Dims[0] * Dims[1])) };
      bool interior = true;
      for (int n = 0; n < 27; ++n)
      {
        const int q[3] = { ijk[0] + n % 3 - 1, ijk[1] + (n / 3) % 3 - 1, ijk[2] + n / 9 - 1 };
        interior &= values[(q[2] * Dims[1] + q[1]) * Dims[0] + q[0]] > BoneThreshold;
      }
      double boneFraction = 0.0;
      for (int n = 0; n < 64; ++n)
      {
        const double sub[4] = { ijk[0] - 0.375 + 0.25 * (n % 4), ijk[1] - 0.375 + 0.25 * ((n / 4) % 4), ijk[2] - 0.375 + 0.25 * (n / 16), 1.0 };
        double ras[4];
        ijkToRAS->MultiplyPoint(sub, ras);
        const double r = std::sqrt(ras[0] * ras[0] + ras[1] * ras[1] + ras[2] * ras[2]);
        boneFraction += (r >= BoneInner && r <= BoneOuter) ? 1.0 / 64.0 : 0.0;
      }
      if (interior || fraction[id] > 1.0 - boneFraction + 0.1)
      {
        std::cerr << "bone voxel " << id << " was carved (removed fraction " << fraction[id] << ", bone fraction " << boneFraction << ")" << std::endl;
        return EXIT_FAILURE;
      }
    }
    tissueRemoved += values[id] > Iso ? fraction[id] : 0.0;
  }
  tissueRemoved *= Spacing[0] * Spacing[1] * Spacing[2];
  CHECK_DOUBLE_TOLERANCE(tissueRemoved, ExactLocalNormalVolume(radius, 10.0), 0.06 * ExactLocalNormalVolume(radius, 10.0));
  CHECK_BOOL(field->Undo(), true);
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), 0.0, 1e-9);

  // Bad depths: nothing carved, the plan kept.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(planner->Carve(field, 0.0), false);
  CHECK_BOOL(planner->Carve(field, 50.0), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(std::string(planner->GetErrorMessage()).find("beyond the planned maximum depth") != std::string::npos, true);
  CHECK_DOUBLE_TOLERANCE(field->ComputeRemovedVolume(), 0.0, 1e-9);
  CHECK_BOOL(planner->HasPlan(), true);

  // Bad outlines: a clear message, and the previous plan stays.
  vtkNew<vtkPoints> two;
  two->InsertNextPoint(0.0, 0.0, SkinRadius);
  two->InsertNextPoint(3.0, 0.0, std::sqrt(SkinRadius * SkinRadius - 9.0));
  planner->SetOutline(two);
  CHECK_BOOL(Fails(planner, "at least 3"), true);
  vtkNew<vtkPoints> eight;
  Circle(radius, 240, eight, true);
  planner->SetOutline(eight);
  CHECK_BOOL(Fails(planner, "crosses itself"), true);
  vtkNew<vtkPoints> floating;
  Circle(radius, 240, floating);
  floating->SetPoint(10, 8.0, 6.0, 33.0); // 4.5 mm above the skin
  planner->SetOutline(floating);
  CHECK_BOOL(Fails(planner, "from the skin"), true);
  planner->SetOutline(outline);
  planner->SetMaximumDepth(1000.0);
  CHECK_BOOL(Fails(planner, "beyond the CT"), true);
  planner->SetMaximumDepth(12.0);
  CHECK_BOOL(planner->HasPlan(), true);
  CHECK_BOOL(planner->Carve(field, 4.0), true);

  // Nothing soft under the outline: refused, nothing carved.
  vtkNew<vtkImageData> boneCT;
  MakeCT(boneCT, ijkToRAS, true);
  vtkNew<vtkVolumeCutResectionPlanner> bare;
  bare->SetAnatomy(boneCT, ijkToRAS);
  bare->SetSkinIsoValue(Iso);
  bare->SetSoftTissueRange(Iso, BoneThreshold);
  bare->SetMaximumDepth(12.0);
  bare->SetOutline(outline);
  CHECK_BOOL(Fails(bare, "no soft tissue"), true);
  CHECK_BOOL(bare->HasPlan(), false);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(bare->Carve(field, 4.0), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  return EXIT_SUCCESS;
}
