// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The wall a burr leaves against a protected structure known only as voxels:
// as smooth as the structure's smoothed surface, not the voxels' stairs, and
// still nothing removed inside the structure's voxels.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutProtection.h"

#include <vtkAddonTestingMacros.h>

#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
struct Stroke
{
  double Start[3];
  double End[3];
  double Radius;
};

// Distance (mm) from p to a capsule, negative inside.
double CapsuleDistance(const Stroke& stroke, const double p[3])
{
  double axis[3];
  double toPoint[3];
  vtkMath::Subtract(stroke.End, stroke.Start, axis);
  vtkMath::Subtract(p, stroke.Start, toPoint);
  const double t = std::max(0.0, std::min(1.0, vtkMath::Dot(toPoint, axis) / vtkMath::Dot(axis, axis)));
  double nearest[3];
  for (int c = 0; c < 3; ++c)
  {
    nearest[c] = stroke.Start[c] + t * axis[c];
  }
  return std::sqrt(vtkMath::Distance2BetweenPoints(p, nearest)) - stroke.Radius;
}

// A ball of radius 4 mm, off the grid, labelled on a 0.5 mm grid (the voxels
// whose centre lies inside) and protected; the rest is cuttable bone. Three
// burr strokes from different sides drive into it. Along rays from the ball's
// centre through the parts all strokes' burrs cover with room to spare, the
// field's surface (the wall) is found by bisection and compared with the
// analytic sphere.
int TestWallAgainstProtectedBall(double smoothing, double& rms, double& worst, double& roughness, double& removedInside, double& removedBeside)
{
  const int dims[3] = { 40, 40, 40 };
  const double spacing = 0.5;
  vtkNew<vtkMatrix4x4> ijkToRas;
  ijkToRas->Identity();
  ijkToRas->SetElement(0, 0, -spacing); // x runs right to left, as in Slicer's RAS
  ijkToRas->SetElement(1, 1, spacing);
  ijkToRas->SetElement(2, 2, spacing);
  ijkToRas->SetElement(0, 3, 11.0);
  ijkToRas->SetElement(1, 3, -6.0);
  ijkToRas->SetElement(2, 3, 2.0);
  vtkNew<vtkVolumeCutField> field;
  CHECK_BOOL(field->Initialize(dims, ijkToRas, 2), true);

  const double centerIndex[4] = { 19.3, 20.15, 19.7, 1.0 };
  double center[4];
  ijkToRas->MultiplyPoint(centerIndex, center);
  const double radius = 4.0;
  vtkNew<vtkImageData> labels;
  labels->SetDimensions(dims[0], dims[1], dims[2]);
  labels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  unsigned char* voxels = static_cast<unsigned char*>(labels->GetScalarPointer());
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const double d[3] = { (i - centerIndex[0]) * spacing, (j - centerIndex[1]) * spacing, (k - centerIndex[2]) * spacing };
        voxels[(static_cast<size_t>(k) * dims[1] + j) * dims[0] + i] = vtkMath::Norm(d) <= radius ? 1 : 0;
      }
    }
  }
  CHECK_BOOL(field->SetProtectedLabels(labels), true);
  if (smoothing >= 0.0) // else the default
  {
    field->GetProtection()->SetSurfaceSmoothing(smoothing);
  }

  std::vector<Stroke> strokes;
  const double directions[3][3] = { { 1.0, 0.0, 0.0 }, { 0.6, 0.8, 0.0 }, { -0.3, 0.5, 0.812404 } };
  for (const auto& direction : directions)
  {
    Stroke stroke;
    for (int c = 0; c < 3; ++c)
    {
      stroke.Start[c] = center[c] + 8.5 * direction[c];
      stroke.End[c] = center[c] + (radius - 0.5) * direction[c];
    }
    stroke.Radius = 2.75;
    CHECK_BOOL(field->CutCapsule(stroke.Start, stroke.End, stroke.Radius), true);
    strokes.push_back(stroke);
  }
  CHECK_BOOL(field->GetMaximumContactDepth() > 1.0, true);

  // Rays through a Fibonacci sphere, kept where some burr covers the ray
  // from a voxel inside the sphere to a voxel outside it.
  const int rayCount = 4000;
  double sum2 = 0.0;
  std::vector<std::array<double, 4>> walls; // ray, deviation
  worst = 0.0;
  int measured = 0;
  for (int n = 0; n < rayCount; ++n)
  {
    const double z = 1.0 - (2.0 * n + 1.0) / rayCount;
    const double around = n * vtkMath::Pi() * (3.0 - std::sqrt(5.0));
    const double ray[3] = { std::sqrt(1.0 - z * z) * std::cos(around), std::sqrt(1.0 - z * z) * std::sin(around), z };
    auto at = [&](double t, double p[3]) {
      for (int c = 0; c < 3; ++c)
      {
        p[c] = center[c] + t * ray[c];
      }
    };
    double inner[3];
    double outer[3];
    at(radius - spacing, inner);
    at(radius + spacing, outer);
    bool covered = false;
    for (const Stroke& stroke : strokes)
    {
      covered |= CapsuleDistance(stroke, inner) < -0.5 && CapsuleDistance(stroke, outer) < -0.5;
    }
    if (!covered)
    {
      continue;
    }
    // Kept (positive) inside, removed (negative) beyond the wall.
    double p[3];
    at(radius - spacing, p);
    CHECK_BOOL(field->GetSignedDistance(p) > 0.0, true);
    at(radius + spacing, p);
    CHECK_BOOL(field->GetSignedDistance(p) < 0.0, true);
    double low = radius - spacing;
    double high = radius + spacing;
    for (int step = 0; step < 40; ++step)
    {
      const double middle = 0.5 * (low + high);
      at(middle, p);
      (field->GetSignedDistance(p) > 0.0 ? low : high) = middle;
    }
    const double deviation = 0.5 * (low + high) - radius;
    sum2 += deviation * deviation;
    walls.push_back({ ray[0], ray[1], ray[2], deviation });
    worst = std::max(worst, std::abs(deviation));
    ++measured;
  }
  CHECK_BOOL(measured > 300, true);
  rms = std::sqrt(sum2 / measured);
  // Steps: how far each ray's wall lies from the mean of its neighbours'
  // within 8 degrees (0.56 mm of the sphere, about a voxel), which a smooth
  // wall follows and a voxel step does not.
  double steps2 = 0.0;
  const double near = std::cos(vtkMath::RadiansFromDegrees(8.0));
  for (const auto& wall : walls)
  {
    double neighbours = 0.0;
    int count = 0;
    for (const auto& other : walls)
    {
      if (&other != &wall && wall[0] * other[0] + wall[1] * other[1] + wall[2] * other[2] > near)
      {
        neighbours += other[3];
        ++count;
      }
    }
    const double step = count ? wall[3] - neighbours / count : 0.0;
    steps2 += step * step;
  }
  roughness = std::sqrt(steps2 / measured);

  vtkNew<vtkImageData> fraction;
  field->ExportRemovedFraction(fraction);
  removedInside = 0.0;
  removedBeside = 0.0;
  const float* removed = static_cast<const float*>(fraction->GetScalarPointer());
  for (vtkIdType id = 0; id < static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2]; ++id)
  {
    (voxels[id] ? removedInside : removedBeside) += removed[id];
  }
  std::cout << "wall against a protected ball (shield smoothing " << field->GetProtection()->GetSurfaceSmoothing() << " voxels): " << measured << " rays, deviation from the sphere RMS "
            << rms << " mm, max " << worst << " mm, steps between neighbouring rays RMS " << roughness << " mm (voxel " << spacing << " mm); removed inside its voxels " << removedInside << ", beside "
            << removedBeside << " voxels" << std::endl;
  return EXIT_SUCCESS;
}
} // namespace

int vtkVolumeCutProtectionTest2(int, char*[])
{
  const double voxel = 0.5;
  double rms = 0.0;
  double worst = 0.0;
  double steps = 0.0;
  double inside = 0.0;
  double beside = 0.0;
  // The voxel faces (smoothing 0): the stairs this test is about, as a check that it sees them.
  CHECK_EXIT_SUCCESS(TestWallAgainstProtectedBall(0.0, rms, worst, steps, inside, beside));
  CHECK_BOOL(inside == 0.0, true);
  CHECK_BOOL(rms > 0.25 * voxel && worst > 0.5 * voxel, true);
  const double voxelSteps = steps;
  // The default shield: the structure's smoothed surface, as the renderer draws it.
  CHECK_EXIT_SUCCESS(TestWallAgainstProtectedBall(-1.0, rms, worst, steps, inside, beside));
  CHECK_BOOL(inside == 0.0, true);
  CHECK_BOOL(beside > 100.0, true);
  CHECK_BOOL(rms <= 0.2 * voxel, true);
  CHECK_BOOL(worst <= 0.4 * voxel, true);
  CHECK_BOOL(steps <= 0.1 * voxel && steps < 0.5 * voxelSteps, true);
  return EXIT_SUCCESS;
}
