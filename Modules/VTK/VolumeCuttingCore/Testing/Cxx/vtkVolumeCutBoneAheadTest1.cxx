// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The bone left ahead of a burr, against an analytic slab: a 3.0 mm plate of
// bone drilled from above leaves the wall the burr's depth says, read within
// half a voxel, straight ahead and at an angle; nothing ahead, a wall going
// on beyond the scan and bad input read as documented. Prints the query's cost.
#include "vtkVolumeCutBoneAhead.h"
#include "vtkVolumeCutField.h"

#include <vtkAddonTestingMacros.h>

#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkTestingOutputWindow.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
constexpr double Spacing = 0.2;
constexpr double SlabBottom = 0.0;
constexpr double SlabTop = 3.0;

// A 40 x 40 x 40 grid at 0.2 mm, z from -3.9 to 3.9 mm: voxel centres fall half a voxel off the slab's faces,
// so the interpolated mask crosses one half exactly on them.
void MakeSlab(vtkImageData* labels, vtkMatrix4x4* ijkToRAS)
{
  const int n = 40;
  labels->SetDimensions(n, n, n);
  labels->AllocateScalars(VTK_UNSIGNED_SHORT, 1);
  ijkToRAS->Identity();
  for (int axis = 0; axis < 3; ++axis)
  {
    ijkToRAS->SetElement(axis, axis, Spacing);
    ijkToRAS->SetElement(axis, 3, -0.5 * (n - 1) * Spacing);
  }
  auto* values = static_cast<unsigned short*>(labels->GetScalarPointer());
  for (int k = 0; k < n; ++k)
  {
    const double z = -0.5 * (n - 1) * Spacing + k * Spacing;
    for (int ij = 0; ij < n * n; ++ij)
    {
      values[k * n * n + ij] = (z > SlabBottom && z < SlabTop) ? 3 : 0;
    }
  }
}
} // namespace

int vtkVolumeCutBoneAheadTest1(int, char*[])
{
  vtkNew<vtkImageData> labels;
  vtkNew<vtkMatrix4x4> ijkToRAS;
  MakeSlab(labels, ijkToRAS);
  vtkNew<vtkVolumeCutBoneAhead> ahead;
  CHECK_BOOL(ahead->SetBone(labels, ijkToRAS), true);
  const double halfVoxel = 0.5 * Spacing;
  const double down[3] = { 0.0, 0.0, -7.0 }; // any length

  // Uncut: from 1 mm above the plate, the whole 3.0 mm, the gap 1 mm.
  ahead->SetMaximumThickness(5.0);
  const double above[3] = { 0.3, -0.2, 4.0 };
  CHECK_DOUBLE_TOLERANCE(ahead->Measure(above, down), SlabTop - SlabBottom, halfVoxel);
  CHECK_DOUBLE_TOLERANCE(ahead->GetLastGap(), 1.0, halfVoxel);

  // Drilled with a 1 mm burr (radius 1) from above down to z = 1.0: 1.0 mm left under its tip.
  vtkNew<vtkVolumeCutField> field;
  int dims[3];
  labels->GetDimensions(dims);
  CHECK_BOOL(field->Initialize(dims, ijkToRAS, 2), true);
  ahead->SetCutField(field);
  const double radius = 1.0;
  const double top[3] = { 0.0, 0.0, 4.0 };
  double centre[3] = { 0.0, 0.0, 1.0 + radius };
  CHECK_BOOL(field->CutCapsule(top, centre, radius), true);
  double tip[3] = { centre[0], centre[1], centre[2] - radius };
  const double thickness = ahead->Measure(tip, down);
  std::cout << "slab 3.0 mm drilled to 1.0 mm: reads " << thickness << " mm (error " << thickness - 1.0 << " mm, voxel " << Spacing << " mm)" << std::endl;
  CHECK_DOUBLE_TOLERANCE(thickness, 1.0, halfVoxel);
  CHECK_DOUBLE_TOLERANCE(ahead->GetLastGap(), 0.0, halfVoxel);

  // Deeper: 0.4 mm left; at 30 degrees from the plate's normal the wall along the line is 0.4 / cos 30.
  centre[2] = 0.4 + radius;
  CHECK_BOOL(field->CutCapsule(top, centre, radius), true);
  tip[2] = centre[2] - radius;
  CHECK_DOUBLE_TOLERANCE(ahead->Measure(tip, down), 0.4, halfVoxel);
  const double angle = vtkMath::RadiansFromDegrees(30.0);
  const double slanted[3] = { std::sin(angle), 0.0, -std::cos(angle) };
  const double slantedTip[3] = { centre[0] + radius * slanted[0], centre[1], centre[2] + radius * slanted[2] };
  // The sphere's surface at 30 degrees sits above the floor: the wall from there is (its height) / cos 30.
  const double expected = slantedTip[2] / std::cos(angle);
  CHECK_DOUBLE_TOLERANCE(ahead->Measure(slantedTip, slanted), expected, halfVoxel);

  // Through: nothing ahead (+inf). Sideways in the hole: the hole's wall, as thick as the rest of the plate reaches.
  centre[2] = -0.5 + radius;
  CHECK_BOOL(field->CutCapsule(top, centre, radius), true);
  tip[2] = centre[2] - radius;
  CHECK_BOOL(std::isinf(ahead->Measure(tip, down)), true);
  // A wall going on beyond the scan reads as MaximumThickness.
  ahead->SetMaximumThickness(20.0);
  const double sideways[3] = { 1.0, 0.0, 0.0 };
  const double inWall[3] = { 0.0, 0.0, 1.5 };
  CHECK_DOUBLE_TOLERANCE(ahead->Measure(inWall, sideways), 20.0, 1e-12);
  ahead->SetMaximumThickness(4.0);
  // Up from below the plate, beyond Range: nothing ahead.
  const double below[3] = { 2.0, 2.0, -3.5 };
  const double up[3] = { 0.0, 0.0, 1.0 };
  ahead->SetRange(2.0);
  CHECK_BOOL(std::isinf(ahead->Measure(below, up)), true);
  ahead->SetRange(4.0);
  CHECK_DOUBLE_TOLERANCE(ahead->Measure(below, up), 3.0, halfVoxel);

  // Bad input: refused, named, nothing lost.
  const double none[3] = { 0.0, 0.0, 0.0 };
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(std::isnan(ahead->Measure(tip, none)), true);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  vtkNew<vtkImageData> empty;
  empty->SetDimensions(4, 4, 4);
  empty->AllocateScalars(VTK_UNSIGNED_SHORT, 1);
  std::fill_n(static_cast<unsigned short*>(empty->GetScalarPointer()), 64, 0);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(ahead->SetBone(empty, ijkToRAS), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  vtkNew<vtkMatrix4x4> singular;
  singular->SetElement(2, 2, 0.0);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(ahead->SetBone(labels, singular), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  vtkNew<vtkVolumeCutBoneAhead> noBone;
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(std::isnan(noBone->Measure(tip, down)), true);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_DOUBLE_TOLERANCE(ahead->Measure(below, up), 3.0, halfVoxel); // the bone set before is kept

  // Cost: a burr on a 1 mm wall under 1 mm of gap, the cut field read at every bone sample.
  const double probe[3] = { 0.0, 0.0, 1.4 };
  std::vector<double> times;
  for (int n = 0; n < 2000; ++n)
  {
    const auto start = std::chrono::steady_clock::now();
    const double wall = ahead->Measure(probe, down);
    times.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
    if (!(wall > 0.0))
    {
      std::cerr << "no wall under the probe" << std::endl;
      return EXIT_FAILURE;
    }
  }
  std::sort(times.begin(), times.end());
  std::cout << "query cost: p50 " << times[times.size() / 2] << " us, p99 " << times[times.size() * 99 / 100] << " us" << std::endl;
  return EXIT_SUCCESS;
}
