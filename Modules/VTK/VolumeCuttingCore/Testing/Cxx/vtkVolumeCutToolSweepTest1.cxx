// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The shortcuts that let non-spherical tools keep up with a haptic loop:
// the cylinder's closed-form translated sweep agrees with a dense union of
// copies (exactly across its axis, within the step along it); the regions a
// tool "leaves behind" really get no nearer to the moving tool; and a
// stroke's continued sweeps, which skip those regions and their first pose,
// cut the same field as sweeps that recompute everything.
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFieldComparison.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>
#include <vtkTransform.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
/// The distance to the tool translated by t * motion, t in [0, 1], as the minimum over many copies.
double DenseSweepDistance(vtkVolumeCutTool* tool, const double motion[3], const double point[3], int copies)
{
  double nearest = 1e300;
  for (int n = 0; n <= copies; ++n)
  {
    const double t = static_cast<double>(n) / copies;
    const double local[3] = { point[0] - t * motion[0], point[1] - t * motion[1], point[2] - t * motion[2] };
    nearest = std::min(nearest, tool->EvaluateDistance(local));
  }
  return nearest;
}

int CheckTranslatedSweep(vtkVolumeCutCylinderTool* cylinder, const double motion[3], double step, double tolerance)
{
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(3);
  const int count = 512;
  const double extent = cylinder->GetBoundingRadius() + vtkMath::Norm(motion) + 1.0;
  std::vector<float> x(count), y(count), z(count), swept(count);
  for (int n = 0; n < count; ++n)
  {
    x[n] = static_cast<float>(random->GetNextRangeValue(-extent, extent));
    y[n] = static_cast<float>(random->GetNextRangeValue(-extent, extent));
    z[n] = static_cast<float>(random->GetNextRangeValue(-extent, extent));
  }
  if (!cylinder->EvaluateTranslatedDistances(motion, step, x.data(), y.data(), z.data(), count, swept.data()))
  {
    std::cerr << "the cylinder has no translated sweep" << std::endl;
    return EXIT_FAILURE;
  }
  double worst = 0.0;
  for (int n = 0; n < count; ++n)
  {
    const double point[3] = { x[n], y[n], z[n] };
    worst = std::max(worst, std::abs(swept[n] - DenseSweepDistance(cylinder, motion, point, 2000)));
  }
  std::cout << "motion " << motion[0] << " " << motion[1] << " " << motion[2] << ": swept distance within " << worst << " mm of 2001 copies"
            << std::endl;
  if (!(worst <= tolerance))
  {
    std::cerr << "the translated sweep differs by " << worst << " mm (tolerance " << tolerance << ")" << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}

/// Where IsLeftBehind says so, moving the tool along the motion never brings it nearer.
int CheckLeftBehind(vtkVolumeCutTool* tool, const char* name)
{
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(11);
  const double extent = tool->GetBoundingRadius() + 2.0;
  int behind = 0;
  for (int trial = 0; trial < 3000; ++trial)
  {
    const double center[3] = { random->GetNextRangeValue(-extent, extent), random->GetNextRangeValue(-extent, extent),
      random->GetNextRangeValue(-extent, extent) };
    const double radius = random->GetNextRangeValue(0.05, 1.2);
    double motion[3] = { random->GetNextRangeValue(-1.0, 1.0), random->GetNextRangeValue(-1.0, 1.0), random->GetNextRangeValue(-1.0, 1.0) };
    if (trial % 3 == 0)
    {
      motion[2] = 0.0; // across a cylinder's axis
    }
    else if (trial % 3 == 1)
    {
      motion[0] = motion[1] = 0.0; // along it
    }
    if (!tool->IsLeftBehind(center, radius, motion))
    {
      continue;
    }
    ++behind;
    for (int sample = 0; sample < 40; ++sample)
    {
      double direction[3] = { random->GetNextRangeValue(-1.0, 1.0), random->GetNextRangeValue(-1.0, 1.0), random->GetNextRangeValue(-1.0, 1.0) };
      vtkMath::Normalize(direction);
      const double r = radius * random->GetNextValue();
      const double point[3] = { center[0] + r * direction[0], center[1] + r * direction[1], center[2] + r * direction[2] };
      const double before = tool->EvaluateDistance(point);
      for (double t : { 0.01, 0.1, 0.5, 1.0 })
      {
        const double moved[3] = { point[0] - t * motion[0], point[1] - t * motion[1], point[2] - t * motion[2] };
        if (tool->EvaluateDistance(moved) < before - 1e-9)
        {
          std::cerr << name << ": a region said to be left behind got nearer to the tool" << std::endl;
          return EXIT_FAILURE;
        }
      }
    }
  }
  std::cout << name << ": " << behind << " of 3000 balls left behind" << std::endl;
  return behind > 100 ? EXIT_SUCCESS : EXIT_FAILURE;
}

/// A stroke of continued translations, or the same sweeps each computed in full.
void CutStroke(vtkVolumeCutField* field, vtkVolumeCutTool* tool, bool continued)
{
  vtkNew<vtkMatrix4x4> previous;
  for (int n = 0; n <= 30; ++n)
  {
    vtkNew<vtkTransform> pose;
    // Across the tool's axis first, then obliquely, then along it.
    const double s = 0.3 * n;
    pose->Translate(8.0 + s, 9.0 + 0.4 * s, 10.0 + (n < 20 ? 0.02 * s : 0.4 * (s - 6.0)));
    pose->RotateWXYZ(30.0, 0.2, 1.0, 0.1);
    if (!continued)
    {
      field->ResetContact(); // forgets the last sweep: no shortcut
    }
    field->CutToolSweep(tool, n == 0 ? pose->GetMatrix() : previous.GetPointer(), pose->GetMatrix());
    previous->DeepCopy(pose->GetMatrix());
  }
}

int CheckContinuedStroke(vtkVolumeCutTool* tool, const char* name)
{
  vtkNew<vtkTransform> grid;
  grid->RotateWXYZ(17.0, 0.1, 0.3, 1.0);
  grid->Scale(0.5, 0.45, 0.6);
  const int dims[3] = { 56, 60, 52 };
  vtkNew<vtkVolumeCutField> continued;
  continued->Initialize(dims, grid->GetMatrix(), 2);
  vtkNew<vtkVolumeCutField> full;
  full->Initialize(dims, grid->GetMatrix(), 2);
  CutStroke(continued, tool, true);
  CutStroke(full, tool, false);
  int worst = 0;
  long differing = 0;
  CompareFieldSamples(continued, full, worst, differing);
  std::cout << name << ": continued stroke within " << worst << " quanta of the full computation, removed "
            << continued->ComputeRemovedVolume() << " mm3" << std::endl;
  // The same arithmetic skipped where it cannot lower anything: at most a
  // rounding of the first pose's copy, one quantum (1e-5 mm).
  return worst <= 1 && continued->ComputeRemovedVolume() > 50.0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
} // namespace

int vtkVolumeCutToolSweepTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkNew<vtkVolumeCutCylinderTool> burr;
  burr->SetRadius(2.5);
  burr->SetLength(5.0);
  vtkNew<vtkVolumeCutCylinderTool> disk;
  disk->SetRadius(10.0);
  disk->SetLength(0.5);
  vtkNew<vtkVolumeCutBoxTool> blade;
  blade->SetSize(10.0, 0.6, 25.0);

  // Across the axis the sweep is exact (the dense copies are within 1e-4 mm
  // of it on curved parts); with a motion along the axis it is within the step.
  const double step = 0.0825;
  const double across[3] = { 0.4, -0.3, 0.0 };
  const double oblique[3] = { 0.3, 0.2, 0.35 };
  const double along[3] = { 0.0, 0.0, 0.5 };
  CHECK_EXIT_SUCCESS(CheckTranslatedSweep(burr, across, step, 2e-4));
  CHECK_EXIT_SUCCESS(CheckTranslatedSweep(disk, across, step, 2e-4));
  CHECK_EXIT_SUCCESS(CheckTranslatedSweep(burr, oblique, step, step));
  CHECK_EXIT_SUCCESS(CheckTranslatedSweep(burr, along, step, step));
  // Tools without a closed form say so.
  float point = 0.0f;
  float distance = 0.0f;
  CHECK_BOOL(blade->EvaluateTranslatedDistances(across, step, &point, &point, &point, 1, &distance), false);

  CHECK_EXIT_SUCCESS(CheckLeftBehind(burr, "cylinder burr"));
  CHECK_EXIT_SUCCESS(CheckLeftBehind(disk, "disk saw"));
  CHECK_EXIT_SUCCESS(CheckLeftBehind(blade, "blade"));

  CHECK_EXIT_SUCCESS(CheckContinuedStroke(burr, "cylinder burr"));
  CHECK_EXIT_SUCCESS(CheckContinuedStroke(disk, "disk saw"));
  CHECK_EXIT_SUCCESS(CheckContinuedStroke(blade, "blade"));
  return EXIT_SUCCESS;
}
