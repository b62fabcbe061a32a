// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The batch distances the cut field's writer uses (EvaluateDistances, single
// precision, vectorised for the closed-form shapes) agree with each tool's
// EvaluateDistance, inside, on and around the surface.
#include "vtkVolumeCutBoxTool.h"
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutEllipsoidTool.h"
#include "vtkVolumeCutPrismTool.h"

#include <vtkAddonTestingMacros.h>

#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>

#include <cmath>
#include <iostream>
#include <vector>

namespace
{
int CheckBatchAgrees(vtkVolumeCutTool* tool, const char* name)
{
  // Points out to twice the bounding radius, plus the centre (a special case
  // of the ellipsoid's formula).
  const int count = 1001;
  const double extent = 2.0 * tool->GetBoundingRadius();
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(7);
  std::vector<float> x(count), y(count), z(count), batch(count);
  for (int n = 1; n < count; ++n)
  {
    for (std::vector<float>* axis : { &x, &y, &z })
    {
      (*axis)[n] = static_cast<float>(random->GetNextRangeValue(-extent, extent));
    }
  }
  x[0] = y[0] = z[0] = 0.0f;
  tool->EvaluateDistances(x.data(), y.data(), z.data(), count, batch.data());
  double worst = 0.0;
  for (int n = 0; n < count; ++n)
  {
    const double local[3] = { x[n], y[n], z[n] };
    worst = std::max(worst, std::abs(batch[n] - tool->EvaluateDistance(local)));
  }
  // Single precision on millimetres: a few 1e-6 mm, far below the field's quantum.
  if (!(worst <= 1e-5))
  {
    std::cerr << name << ": batch distances differ by up to " << worst << " mm" << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
}

int vtkVolumeCutToolTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkNew<vtkVolumeCutCylinderTool> cylinder;
  cylinder->SetRadius(2.5);
  cylinder->SetLength(5.0);
  CHECK_EXIT_SUCCESS(CheckBatchAgrees(cylinder, "cylinder"));
  vtkNew<vtkVolumeCutCylinderTool> disk; // a disk saw
  disk->SetRadius(6.0);
  disk->SetLength(0.3);
  CHECK_EXIT_SUCCESS(CheckBatchAgrees(disk, "disk"));
  vtkNew<vtkVolumeCutEllipsoidTool> ellipsoid;
  ellipsoid->SetRadii(1.5, 2.0, 3.0);
  CHECK_EXIT_SUCCESS(CheckBatchAgrees(ellipsoid, "ellipsoid"));
  vtkNew<vtkVolumeCutBoxTool> blade;
  blade->SetSize(10.0, 0.4, 5.0);
  CHECK_EXIT_SUCCESS(CheckBatchAgrees(blade, "blade"));
  // A shape without a batch form of its own: the default loop.
  vtkNew<vtkVolumeCutPrismTool> prism;
  prism->AddVertex(-1.0, -1.0);
  prism->AddVertex(1.0, -1.0);
  prism->AddVertex(0.5, 1.5);
  prism->SetDepth(2.0);
  CHECK_BOOL(prism->IsValid(), true);
  CHECK_EXIT_SUCCESS(CheckBatchAgrees(prism, "prism"));
  return EXIT_SUCCESS;
}
