// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The cut field's writer visits only the bricks near a tool's box
// (vtkVolumeCutTool::GetLocalHalfExtents) and, for a translated sweep with a
// closed form, only those the sweep's own distance brings within the band,
// and in those only the z-slices that the tool's bounds
// (vtkVolumeCutTool::BoundTranslatedDistances) say may change: within the
// band and, for a cut, below the most the field holds there. Random strokes
// of a disk saw, a cylindrical burr and a blade, rotated and translated on an
// oblique grid, between spherical burr strokes, and a disk saw climbing a
// helix on a grid along its axis (where whole slices above and below the
// blade are skipped), cut and restored, must give sample by sample the same
// field as a writer that visits every brick of the bounding sphere's cube and
// evaluates every slice of every one not left behind.
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldComparison.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMatrix4x4.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <vtkTransform.h>

#include <cmath>
#include <iostream>
#include <limits>

namespace
{
/// The wrapped tool, except that it claims no box tighter than its bounding
/// sphere, bounds no slices and, asked for one translated distance (the
/// writer's test of a brick), answers "inside": every brick of the cube is
/// evaluated in full.
class ExhaustiveTool : public vtkVolumeCutTool
{
public:
  static ExhaustiveTool* New()
  {
    ExhaustiveTool* tool = new ExhaustiveTool;
    tool->InitializeObjectBase();
    return tool;
  }
  vtkTypeMacro(ExhaustiveTool, vtkVolumeCutTool);

  vtkSmartPointer<vtkVolumeCutTool> Wrapped;

  double EvaluateDistance(const double local[3]) override { return this->Wrapped->EvaluateDistance(local); }
  void EvaluateDistances(const float* x, const float* y, const float* z, int count, float* distances) override
  {
    this->Wrapped->EvaluateDistances(x, y, z, count, distances);
  }
  double GetBoundingRadius() override { return this->Wrapped->GetBoundingRadius(); }
  bool IsLeftBehind(const double center[3], double radius, const double motion[3]) override
  {
    return this->Wrapped->IsLeftBehind(center, radius, motion);
  }
  bool EvaluateTranslatedDistances(const double motion[3], double step, const float* x, const float* y, const float* z, int count, float* distances) override
  {
    const bool closedForm = this->Wrapped->EvaluateTranslatedDistances(motion, step, x, y, z, count, distances);
    if (closedForm && count == 1)
    {
      distances[0] = -std::numeric_limits<float>::max();
    }
    return closedForm;
  }
  bool IsValid() override { return this->Wrapped->IsValid(); }

protected:
  ExhaustiveTool() = default;
  ~ExhaustiveTool() override = default;
};

/// Random strokes: continued translations and rotating sweeps of the tool,
/// then a few spherical burr strokes, the same in both fields.
void CutRandomStrokes(vtkVolumeCutField* field, vtkVolumeCutTool* tool, int seed)
{
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(seed);
  for (int path = 0; path < 6; ++path)
  {
    double position[3];
    for (double& coordinate : position)
    {
      coordinate = random->GetNextRangeValue(6.0, 20.0);
    }
    double axis[3] = { random->GetNextRangeValue(-1.0, 1.0), random->GetNextRangeValue(-1.0, 1.0), random->GetNextRangeValue(-1.0, 1.0) };
    double angle = path == 0 ? 0.0 : random->GetNextRangeValue(0.0, 180.0);
    const bool rotating = path % 3 == 2;
    vtkNew<vtkMatrix4x4> previous;
    for (int n = 0; n <= 12; ++n)
    {
      vtkNew<vtkTransform> pose;
      pose->Translate(position);
      pose->RotateWXYZ(angle, axis);
      field->CutToolSweep(tool, n == 0 ? pose->GetMatrix() : previous.GetPointer(), pose->GetMatrix());
      previous->DeepCopy(pose->GetMatrix());
      for (double& coordinate : position)
      {
        coordinate += random->GetNextRangeValue(-0.4, 0.4);
      }
      angle += rotating ? 3.0 : 0.0;
    }
  }
  double p0[3] = { 12.0, 13.0, 11.0 };
  for (int n = 0; n < 10; ++n)
  {
    const double p1[3] = { p0[0] + random->GetNextRangeValue(-0.5, 0.5), p0[1] + random->GetNextRangeValue(-0.5, 0.5),
      p0[2] + random->GetNextRangeValue(-0.5, 0.5) };
    field->CutCapsule(p0, p1, 1.5);
    std::copy(p1, p1 + 3, p0);
  }
}

int CheckPruning(vtkVolumeCutTool* tool, const char* name, int seed)
{
  vtkNew<vtkTransform> grid;
  grid->RotateWXYZ(17.0, 0.1, 0.3, 1.0);
  grid->Scale(0.35, 0.33, 0.4);
  const int dims[3] = { 80, 84, 76 };
  vtkNew<vtkVolumeCutField> pruned;
  pruned->Initialize(dims, grid->GetMatrix(), 2);
  vtkNew<vtkVolumeCutField> exhaustive;
  exhaustive->Initialize(dims, grid->GetMatrix(), 2);
  vtkNew<ExhaustiveTool> reference;
  reference->Wrapped = tool;
  CutRandomStrokes(pruned, tool, seed);
  CutRandomStrokes(exhaustive, reference, seed);
  int worst = 0;
  long differing = 0;
  CompareFieldSamples(pruned, exhaustive, worst, differing);
  std::cout << name << ": " << differing << " samples differ from the exhaustive writer, removed " << pruned->ComputeRemovedVolume() << " mm3 ("
            << pruned->GetNumberOfAllocatedBricks() << " bricks)" << std::endl;
  return differing == 0 && pruned->ComputeRemovedVolume() > 20.0 ? EXIT_SUCCESS : EXIT_FAILURE;
}

/// A disk saw (axis along the grid's k) climbing a helix in small steps, as
/// the haptics benchmark drives it, then backed out along part of it.
void CutHelix(vtkVolumeCutField* field, vtkVolumeCutTool* tool)
{
  vtkNew<vtkMatrix4x4> previous;
  vtkNew<vtkMatrix4x4> pose;
  for (int n = 0; n <= 60; ++n)
  {
    const double angle = n * 0.5 / 8.0;
    pose->SetElement(0, 3, 15.0 + 8.0 * std::cos(angle));
    pose->SetElement(1, 3, 15.0 + 8.0 * std::sin(angle));
    pose->SetElement(2, 3, 12.0 + 0.03 * n);
    field->CutToolSweep(tool, n == 0 ? pose.GetPointer() : previous.GetPointer(), pose);
    previous->DeepCopy(pose);
  }
  for (int n = 0; n < 10; ++n)
  {
    pose->SetElement(0, 3, previous->GetElement(0, 3) - 0.4);
    pose->SetElement(2, 3, previous->GetElement(2, 3) + 0.07);
    field->RestoreToolSweep(tool, previous, pose);
    previous->DeepCopy(pose);
  }
}

int CheckHelix(vtkVolumeCutTool* tool)
{
  vtkNew<vtkMatrix4x4> grid;
  for (int axis = 0; axis < 3; ++axis)
  {
    grid->SetElement(axis, axis, 0.33);
  }
  const int dims[3] = { 96, 96, 64 };
  vtkNew<vtkVolumeCutField> trimmed;
  trimmed->Initialize(dims, grid, 2);
  vtkNew<vtkVolumeCutField> exhaustive;
  exhaustive->Initialize(dims, grid, 2);
  vtkNew<ExhaustiveTool> reference;
  reference->Wrapped = tool;
  CutHelix(trimmed, tool);
  CutHelix(exhaustive, reference);
  int worst = 0;
  long differing = 0;
  CompareFieldSamples(trimmed, exhaustive, worst, differing);
  std::cout << "disk saw on a helix: " << differing << " samples differ from the exhaustive writer (worst " << worst << " quanta), removed "
            << trimmed->ComputeRemovedVolume() << " mm3" << std::endl;
  return differing == 0 && trimmed->ComputeRemovedVolume() > 20.0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
} // namespace

int vtkVolumeCutSweepPruningTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkNew<vtkVolumeCutCylinderTool> disk;
  disk->SetRadius(6.0);
  disk->SetLength(0.5);
  vtkNew<vtkVolumeCutCylinderTool> burr;
  burr->SetRadius(1.25);
  burr->SetLength(5.0);
  vtkNew<vtkVolumeCutBoxTool> blade;
  blade->SetSize(8.0, 0.5, 4.0);
  CHECK_EXIT_SUCCESS(CheckPruning(disk, "disk saw", 3));
  CHECK_EXIT_SUCCESS(CheckPruning(burr, "cylindrical burr", 5));
  CHECK_EXIT_SUCCESS(CheckPruning(blade, "blade", 7));
  vtkNew<vtkVolumeCutCylinderTool> saw;
  saw->SetRadius(5.0);
  saw->SetLength(0.5);
  CHECK_EXIT_SUCCESS(CheckHelix(saw));
  return EXIT_SUCCESS;
}
