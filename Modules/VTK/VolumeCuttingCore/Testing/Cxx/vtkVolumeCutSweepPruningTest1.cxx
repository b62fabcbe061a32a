// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The cut field's writer visits only the bricks near a tool's box
// (vtkVolumeCutTool::GetLocalHalfExtents) and, for a translated sweep with a
// closed form, only those the sweep's own distance brings within the band.
// Random strokes of a disk saw, a cylindrical burr and a blade, rotated and
// translated on an oblique grid, between spherical burr strokes, must cut
// sample by sample the same field as a writer that visits every brick of the
// bounding sphere's cube and evaluates every one not left behind.
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldComparison.h"

#include <vtkAddonTestingMacros.h>

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
/// sphere and, asked for one translated distance (the writer's test of a
/// brick), answers "inside": every brick of the cube is evaluated in full.
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
  return EXIT_SUCCESS;
}
