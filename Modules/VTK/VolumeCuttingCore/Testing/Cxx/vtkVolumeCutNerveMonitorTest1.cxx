// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutCylinderTool.h"
#include "vtkVolumeCutEllipsoidTool.h"
#include "vtkVolumeCutLabelSurface.h"
#include "vtkVolumeCutNerveMonitor.h"
#include "vtkVolumeCutNerveMonitorTesting.h"

#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

#include <vtkCallbackCommand.h>
#include <vtkDoubleArray.h>
#include <vtkImageData.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkTransform.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <thread>
#include <vector>

namespace
{
using Reading = vtkVolumeCutNerveMonitor::Reading;

/// An anatomy grid: dimensions, and IJK-to-RAS with the given spacing, turned about an oblique axis and moved.
struct Grid
{
  int Dimensions[3];
  vtkNew<vtkMatrix4x4> IJKToRAS;

  Grid(const int dims[3], const double spacing[3], double turnDegrees)
  {
    std::copy(dims, dims + 3, this->Dimensions);
    vtkNew<vtkTransform> transform;
    transform->Translate(-12.0, 30.0, 5.0);
    transform->RotateWXYZ(turnDegrees, 0.3, -0.5, 0.8);
    transform->Scale(spacing);
    this->IJKToRAS->DeepCopy(transform->GetMatrix());
  }
  void ToRAS(const double ijk[3], double ras[3]) const
  {
    const double in[4] = { ijk[0], ijk[1], ijk[2], 1.0 };
    double out[4];
    this->IJKToRAS->MultiplyPoint(in, out);
    std::copy(out, out + 3, ras);
  }
  /// The centre of the grid in RAS.
  void Centre(double ras[3]) const
  {
    const double ijk[3] = { 0.5 * (this->Dimensions[0] - 1), 0.5 * (this->Dimensions[1] - 1), 0.5 * (this->Dimensions[2] - 1) };
    this->ToRAS(ijk, ras);
  }
  /// A label image with value where inside(ras) holds at the voxel centre.
  vtkSmartPointer<vtkImageData> Rasterise(const std::function<bool(const double*)>& inside, int value) const
  {
    return vtkVolumeCutNerveMonitorTesting::Rasterise(this->Dimensions, this->IJKToRAS, inside, value);
  }
};

/// An analytic nerve: a cylinder (infinite along its axis) of radius R about a line.
struct Cylinder
{
  double Point[3];
  double Axis[3];
  double Radius;
  double SurfaceDistance(const double p[3]) const
  {
    double d[3] = { p[0] - this->Point[0], p[1] - this->Point[1], p[2] - this->Point[2] };
    const double along = vtkMath::Dot(d, this->Axis);
    for (int axis = 0; axis < 3; ++axis)
    {
      d[axis] -= along * this->Axis[axis];
    }
    return vtkMath::Norm(d) - this->Radius;
  }
};

/// Points on a structure's smoothed surface (RAS), independently of the
/// monitor: the zero set of the trilinear levels crossed along the edges of
/// a grid refine times finer than the voxels.
std::vector<double> SmoothedSurfacePoints(const Grid& grid, vtkImageData* labels, int value, double smoothing, int refine)
{
  const int* dims = grid.Dimensions;
  const unsigned short* voxels = static_cast<const unsigned short*>(labels->GetScalarPointer());
  std::vector<uint16_t> mask(voxels, voxels + static_cast<size_t>(dims[0]) * dims[1] * dims[2]);
  std::vector<std::vector<int>> boxes;
  vtkVolumeCutLabelSurface::ComputeLabelBoxes(mask.data(), dims, { value }, boxes);
  double spacing[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    spacing[axis] = std::sqrt(grid.IJKToRAS->GetElement(0, axis) * grid.IJKToRAS->GetElement(0, axis) + grid.IJKToRAS->GetElement(1, axis) * grid.IJKToRAS->GetElement(1, axis) +
      grid.IJKToRAS->GetElement(2, axis) * grid.IJKToRAS->GetElement(2, axis));
  }
  vtkVolumeCutLabelSurface::Levels levels;
  vtkVolumeCutLabelSurface::Initialize(dims, spacing, boxes[0].data(), smoothing, levels);
  vtkVolumeCutLabelSurface::ComputeSlices(mask.data(), dims, spacing, value, boxes[0].data(), smoothing, 0,
    vtkVolumeCutLabelSurface::GetNumberOfSlices(boxes[0].data(), levels), levels);
  vtkVolumeCutLabelSurface::ExtrapolateEnds(boxes[0].data(), levels);
  const int* box = levels.Box;
  const int n[3] = { box[1] - box[0] + 1, box[3] - box[2] + 1, box[5] - box[4] + 1 };
  auto level = [&](const double ijk[3]) {
    int cell[3];
    double t[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      const double local = std::min(std::max(ijk[axis] - box[2 * axis], 0.0), n[axis] - 1.0);
      cell[axis] = std::min(static_cast<int>(local), std::max(n[axis] - 2, 0));
      t[axis] = local - cell[axis];
    }
    double value = 0.0;
    for (int c = 0; c < 8; ++c)
    {
      const int a = c & 1, b = (c >> 1) & 1, d = (c >> 2) & 1;
      const double weight = (a ? t[0] : 1 - t[0]) * (b ? t[1] : 1 - t[1]) * (d ? t[2] : 1 - t[2]);
      const int i = std::min(cell[0] + a, n[0] - 1), j = std::min(cell[1] + b, n[1] - 1), k = std::min(cell[2] + d, n[2] - 1);
      value += weight * levels.Values[i + static_cast<size_t>(n[0]) * (j + static_cast<size_t>(n[1]) * k)];
    }
    return value;
  };
  std::vector<double> points;
  const double step = 1.0 / refine;
  for (int k = 0; k < (n[2] - 1) * refine; ++k)
  {
    for (int j = 0; j < (n[1] - 1) * refine; ++j)
    {
      for (int i = 0; i < (n[0] - 1) * refine; ++i)
      {
        const double ijk[3] = { box[0] + i * step, box[2] + j * step, box[4] + k * step };
        const double g0 = level(ijk);
        for (int axis = 0; axis < 3; ++axis)
        {
          double next[3] = { ijk[0], ijk[1], ijk[2] };
          next[axis] += step;
          const double g1 = level(next);
          if ((g0 <= 0.0) != (g1 <= 0.0))
          {
            double crossing[3] = { ijk[0], ijk[1], ijk[2] };
            crossing[axis] += step * g0 / (g0 - g1);
            double ras[3];
            grid.ToRAS(crossing, ras);
            points.insert(points.end(), ras, ras + 3);
          }
        }
      }
    }
  }
  return points;
}

double NearestDistance(const std::vector<double>& points, const double p[3])
{
  double best = 1e300;
  for (size_t n = 0; n < points.size(); n += 3)
  {
    best = std::min(best, vtkMath::Distance2BetweenPoints(p, points.data() + n));
  }
  return std::sqrt(best);
}

double Random(vtkMinimalStandardRandomSequence* random, double low, double high)
{
  random->Next();
  return random->GetRangeValue(low, high);
}

/// A random unit vector.
void RandomDirection(vtkMinimalStandardRandomSequence* random, double direction[3])
{
  do
  {
    for (int axis = 0; axis < 3; ++axis)
    {
      direction[axis] = Random(random, -1.0, 1.0);
    }
  } while (vtkMath::Norm(direction) > 1.0 || vtkMath::Norm(direction) < 0.1);
  vtkMath::Normalize(direction);
}

/// Largest errors against the cylinder, over burrs at several distances and
/// radii around its middle (away from the grid's ends): of the distance to
/// the smoothed surface (the field at the centre less the radius), and of
/// the reading where the burr is clear of the shield (where it touches the
/// voxel cubes standing out of the surface, the reading is contact).
struct CylinderErrors
{
  double Surface = 1e9;
  double Reading = 1e9;
  double WorstAt = 0.0;
  int Clear = 0;
};

CylinderErrors CylinderError(const double spacing[3], double turnDegrees, const double axis[3], double radius, int positions)
{
  const double extent = 9.0; // mm: burr centres stay within 4 mm of the axis
  const int dims[3] = { int(extent / spacing[0]), int(extent / spacing[1]), int(extent / spacing[2]) };
  Grid grid(dims, spacing, turnDegrees);
  Cylinder nerve;
  grid.Centre(nerve.Point);
  std::copy(axis, axis + 3, nerve.Axis);
  vtkMath::Normalize(nerve.Axis);
  nerve.Radius = radius;
  auto labels = grid.Rasterise([&](const double* p) { return nerve.SurfaceDistance(p) <= 0.0; }, 7);
  vtkNew<vtkVolumeCutNerveMonitor> monitor;
  monitor->SetGeometry(grid.Dimensions, grid.IJKToRAS);
  monitor->SetRange(3.5); // every burr below is nearer: a smaller band to build
  monitor->SetContactRange(1.5);
  CylinderErrors errors;
  if (monitor->AddStructure("facial nerve", labels, 7) != 0 || monitor->Build() != 1)
  {
    return errors;
  }
  errors.Surface = errors.Reading = 0.0;
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(25);
  const double distances[] = { 0.05, 0.3, 1.0, 2.0 };
  const double burrRadii[] = { 0.5, 1.0 };
  for (int n = 0; n < positions; ++n)
  {
    const double distance = distances[n % 4];
    const double burr = burrRadii[(n / 4) % 2];
    // A point on the axis within 2 mm of the middle, then out along a random normal.
    double normal[3];
    RandomDirection(random, normal);
    const double along = vtkMath::Dot(normal, nerve.Axis);
    for (int a = 0; a < 3; ++a)
    {
      normal[a] -= along * nerve.Axis[a];
    }
    vtkMath::Normalize(normal);
    const double s = Random(random, -2.0, 2.0);
    double centre[3];
    for (int a = 0; a < 3; ++a)
    {
      centre[a] = nerve.Point[a] + s * nerve.Axis[a] + (radius + burr + distance) * normal[a];
    }
    const double surfaceError = std::abs(monitor->GetDistanceAt(0, centre) - burr - distance);
    if (surfaceError > errors.Surface)
    {
      errors.Surface = surfaceError;
      errors.WorstAt = distance;
    }
    Reading reading;
    monitor->Measure(centre, burr, &reading, 1);
    if (reading.Clearance > 0.0)
    {
      ++errors.Clear;
      errors.Reading = std::max(errors.Reading, std::abs(reading.Distance - distance));
    }
    else if (reading.Level != vtkVolumeCutNerveMonitor::Contact || reading.Distance != reading.Clearance)
    {
      errors.Reading = 1e9; // touching the shield reads contact, the clearance
    }
  }
  return errors;
}

int TestCylinderAccuracy()
{
  struct Case
  {
    double Spacing[3];
    double Turn;
    double Axis[3];
    double Radius;
  };
  // The bound for the reading, the distance to the smoothed
  // surface: 0.05 mm from the analytic nerve, on temporal-bone voxels
  // straight and turned. On anisotropic voxels the smoothed surface itself
  // (vtkVolumeCutLabelSurface, shared with the renderer and the shield)
  // departs further from the cylinder, where the nerve's top and bottom
  // run nearly along the slices and their outlines are interpolated
  // linearly across them: the bound is then 0.4 of the slice spacing (the
  // field against that surface is checked to 0.02 mm below).
  const Case cases[] = { { { 0.15, 0.15, 0.15 }, 0.0, { 0.7, -0.4, 0.59 }, 0.8 }, { { 0.15, 0.15, 0.15 }, 33.0, { 0.2, 0.9, -0.3 }, 0.6 },
    { { 0.12, 0.15, 0.25 }, 20.0, { 0.7, -0.4, 0.59 }, 1.0 }, { { 0.2, 0.2, 0.3 }, 0.0, { 1.0, 0.1, 0.05 }, 1.2 } };
  for (const Case& c : cases)
  {
    const CylinderErrors errors = CylinderError(c.Spacing, c.Turn, c.Axis, c.Radius, 64);
    std::cout << "cylinder radius " << c.Radius << " mm, spacing " << c.Spacing[0] << " x " << c.Spacing[1] << " x " << c.Spacing[2]
              << " mm, grid turned " << c.Turn << " degrees: smoothed-surface distance max error " << errors.Surface << " mm (at "
              << errors.WorstAt << " mm); reading " << errors.Reading << " mm over the " << errors.Clear << " burrs clear of the shield"
              << std::endl;
    const double bound = std::max(0.05, 0.4 * std::max({ c.Spacing[0], c.Spacing[1], c.Spacing[2] }));
    CHECK_BOOL(errors.Surface <= bound, true);
    CHECK_BOOL(errors.Reading <= bound, true);
    CHECK_BOOL(errors.Clear >= 40, true);
  }
  return EXIT_SUCCESS;
}

int TestSphereAccuracyAndTools()
{
  const double spacing[3] = { 0.15, 0.18, 0.22 };
  const int dims[3] = { 82, 68, 56 }; // about 12 mm across: every burr below stays inside
  Grid grid(dims, spacing, 15.0);
  double centre[3];
  grid.Centre(centre);
  const double radius = 1.5;
  auto labels = grid.Rasterise([&](const double* p) { return std::sqrt(vtkMath::Distance2BetweenPoints(p, centre)) <= radius; }, 3);
  vtkNew<vtkVolumeCutNerveMonitor> monitor;
  monitor->SetRange(4.0);
  monitor->SetContactRange(3.5); // the clearance exact for every burr and tool below
  CHECK_BOOL(monitor->SetGeometry(grid.Dimensions, grid.IJKToRAS), true);
  CHECK_INT(monitor->AddStructure("vestibule", labels, 3), 0);
  // Before Build: not ready, never a guess.
  Reading reading;
  CHECK_INT(monitor->Measure(centre, 1.0, &reading, 1), 1);
  CHECK_INT(reading.Level, vtkVolumeCutNerveMonitor::NotReady);
  CHECK_BOOL(std::isnan(reading.Distance), true);
  CHECK_BOOL(std::isnan(reading.Clearance), true);
  CHECK_INT(monitor->Build(), 1);
  CHECK_BOOL(monitor->IsBuilt(), true);

  // The reading against the analytic sphere: the smoothed surface's
  // distance within 0.05 mm while the burr is clear of the shield; touching
  // the voxel cubes that stand out of it, contact.
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(3);
  double worst = 0.0;
  int clear = 0;
  for (int n = 0; n < 200; ++n)
  {
    double direction[3];
    RandomDirection(random, direction);
    const double distance = Random(random, 0.02, 2.5);
    const double burr = Random(random, 0.5, 1.5);
    double p[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      p[axis] = centre[axis] + (radius + burr + distance) * direction[axis];
    }
    monitor->Measure(p, burr, &reading, 1);
    CHECK_BOOL(reading.Clearance <= reading.Distance, true);
    worst = std::max(worst, std::abs(monitor->GetDistanceAt(0, p) - burr - distance));
    if (reading.Clearance > 0.0)
    {
      ++clear;
      worst = std::max(worst, std::abs(reading.Distance - distance));
    }
    else
    {
      CHECK_INT(reading.Level, vtkVolumeCutNerveMonitor::Contact);
    }
  }
  std::cout << "sphere radius 1.5 mm, spacing 0.15 x 0.18 x 0.22 mm: max error " << worst << " mm (" << clear << " of 200 burrs clear of the shield)"
            << std::endl;
  CHECK_BOOL(worst <= 0.4 * spacing[2], true); // anisotropic: as for the cylinders
  CHECK_BOOL(clear >= 150, true);
  // Against the two surfaces found independently (the smoothed surface's
  // points, the exact distance to the voxel cubes) the fields are far closer.
  const std::vector<double> surface = SmoothedSurfacePoints(grid, labels, 3, monitor->GetSmoothing(), 3);
  const std::vector<int> voxels = vtkVolumeCutNerveMonitorTesting::VoxelsOf(labels, 3);
  double worstSurface = 0.0, worstShield = 0.0;
  for (int n = 0; n < 60; ++n)
  {
    double direction[3];
    RandomDirection(random, direction);
    const double distance = Random(random, 0.0, 2.5);
    double p[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      p[axis] = centre[axis] + (radius + distance) * direction[axis];
    }
    const double smoothed = NearestDistance(surface, p);
    const double shield = std::min(smoothed, vtkVolumeCutNerveMonitorTesting::VoxelCubeDistance(grid.IJKToRAS, voxels, p));
    worstSurface = std::max(worstSurface, std::abs(monitor->GetDistanceAt(0, p) - smoothed));
    if (shield <= monitor->GetContactRange())
    {
      worstShield = std::max(worstShield, std::abs(monitor->GetClearanceAt(0, p) - shield));
    }
  }
  std::cout << "against the smoothed surface (" << surface.size() / 3 << " points): max error " << worstSurface
            << " mm; the clearance against the shield (that surface and the voxel cubes): " << worstShield << " mm" << std::endl;
  // The monitor's surface is closed across the slices as the shield's is
  // (over the poles, which the levels found here leave open): that moves
  // it there by a few hundredths of a millimetre.
  CHECK_BOOL(worstSurface <= 0.05, true);
  CHECK_BOOL(worstShield <= 0.02, true);

  // Any tool: a sphere given as an ellipsoid reads as the burr does; a
  // cylinder burr against its exact distance to the sphere.
  vtkNew<vtkVolumeCutEllipsoidTool> ball;
  ball->SetRadii(1.2, 1.2, 1.2);
  vtkNew<vtkVolumeCutCylinderTool> cylinder;
  cylinder->SetRadius(0.8);
  cylinder->SetLength(4.0);
  double worstBall = 0.0, worstBallClearance = 0.0, worstCylinder = 0.0;
  for (int n = 0; n < 30; ++n)
  {
    double direction[3];
    RandomDirection(random, direction);
    const double distance = Random(random, 0.1, 2.0);
    vtkNew<vtkTransform> pose;
    pose->Translate(centre[0] + (radius + 1.2 + distance) * direction[0], centre[1] + (radius + 1.2 + distance) * direction[1],
      centre[2] + (radius + 1.2 + distance) * direction[2]);
    pose->RotateWXYZ(Random(random, 0.0, 180.0), 0.2, 0.9, -0.4);
    CHECK_BOOL(monitor->UpdateWithTool(ball, pose->GetMatrix()), true);
    const double* position = pose->GetPosition();
    monitor->Measure(position, 1.2, &reading, 1);
    // Touching, the two clearances are both negative but measured differently
    // (the burr's depth at its centre, the tool's deepest surface point).
    if (reading.Clearance > 0.0 && monitor->GetClearance(0) > 0.0)
    {
      worstBall = std::max(worstBall, std::abs(monitor->GetDistance(0) - reading.Distance));
      worstBallClearance = std::max(worstBallClearance, std::abs(monitor->GetClearance(0) - reading.Clearance));
    }
    CHECK_BOOL(monitor->GetLevel(0) == vtkVolumeCutNerveMonitor::Contact, reading.Clearance <= 0.0 || monitor->GetClearance(0) <= 0.0);
    // The cylinder at a random pose: its exact distance to the sphere's centre, less the radius.
    vtkNew<vtkMatrix4x4> rasToTool;
    vtkMatrix4x4::Invert(pose->GetMatrix(), rasToTool);
    const double in[4] = { centre[0], centre[1], centre[2], 1.0 };
    double local[4];
    rasToTool->MultiplyPoint(in, local);
    const double radial = std::max(0.0, std::hypot(local[0], local[1]) - 0.8);
    const double axial = std::max(0.0, std::abs(local[2]) - 2.0);
    const double exact = std::hypot(radial, axial) - radius;
    CHECK_BOOL(monitor->UpdateWithTool(cylinder, pose->GetMatrix()), true);
    if (exact < 2.5 && monitor->GetClearance(0) > 0.0)
    {
      worstCylinder = std::max(worstCylinder, std::abs(monitor->GetDistance(0) - exact));
    }
  }
  std::cout << "tools on " << monitor->GetNumberOfToolSamples() << " surface points: ellipsoid ball against the burr max difference " << worstBall
            << " mm (clearance " << worstBallClearance << " mm), cylinder burr against the analytic sphere " << worstCylinder << " mm" << std::endl;
  // Points 0.2 mm apart on the ball, and the smoothed field read at them
  // rather than at the centre (its interpolation between samples).
  CHECK_BOOL(worstBall <= 0.035, true);
  CHECK_BOOL(worstBallClearance <= 0.025, true);
  CHECK_BOOL(worstCylinder <= 0.05, true);
  return EXIT_SUCCESS;
}

/// Levels at each threshold, the firing rate, and the events.
int TestLevelsAndEvents()
{
  vtkNew<vtkVolumeCutNerveMonitor> monitor;
  struct Expected
  {
    double Distance;
    int Level;
  };
  const Expected expected[] = { { 10.0, vtkVolumeCutNerveMonitor::Silent }, { 4.001, vtkVolumeCutNerveMonitor::Silent },
    { 4.0, vtkVolumeCutNerveMonitor::SparseClicks }, { 2.001, vtkVolumeCutNerveMonitor::SparseClicks }, { 2.0, vtkVolumeCutNerveMonitor::Bursts },
    { 1.001, vtkVolumeCutNerveMonitor::Bursts }, { 1.0, vtkVolumeCutNerveMonitor::Continuous }, { 0.001, vtkVolumeCutNerveMonitor::Continuous },
    { 0.0, vtkVolumeCutNerveMonitor::Contact }, { -0.5, vtkVolumeCutNerveMonitor::Contact } };
  double previousRate = -1.0;
  for (const Expected& e : expected)
  {
    CHECK_INT(monitor->GetLevelOfDistance(e.Distance), e.Level);
    const double rate = monitor->GetFiringRateOfDistance(e.Distance);
    CHECK_BOOL(rate >= previousRate, true); // rises with proximity
    previousRate = rate;
  }
  CHECK_DOUBLE(monitor->GetFiringRateOfDistance(4.5), 0.0);
  CHECK_DOUBLE(monitor->GetFiringRateOfDistance(0.0), 200.0);
  CHECK_DOUBLE(monitor->GetFiringRateOfDistance(2.0), 50.0);

  CHECK_BOOL(monitor->SetThresholds(6.0, 3.0, 1.5), true);
  CHECK_INT(monitor->GetLevelOfDistance(5.0), vtkVolumeCutNerveMonitor::SparseClicks);
  CHECK_INT(monitor->GetLevelOfDistance(2.5), vtkVolumeCutNerveMonitor::Bursts);
  CHECK_INT(monitor->GetLevelOfDistance(1.2), vtkVolumeCutNerveMonitor::Continuous);
  CHECK_BOOL(monitor->SetThresholds(4.0, 2.0, 1.0), true);

  // A burr approaching a sphere: readings cross every threshold, one event per change of level.
  const double spacing[3] = { 0.2, 0.2, 0.2 };
  const int dims[3] = { 80, 80, 80 };
  Grid grid(dims, spacing, 0.0);
  double centre[3];
  grid.Centre(centre);
  auto labels = grid.Rasterise([&](const double* p) { return std::sqrt(vtkMath::Distance2BetweenPoints(p, centre)) <= 1.0; }, 1);
  monitor->SetGeometry(grid.Dimensions, grid.IJKToRAS);
  CHECK_INT(monitor->AddStructure("nerve", labels, 1), 0);
  monitor->Build();
  int levelEvents = 0;
  vtkNew<vtkCallbackCommand> counter;
  counter->SetClientData(&levelEvents);
  counter->SetCallback([](vtkObject*, unsigned long, void* clientData, void*) { ++*static_cast<int*>(clientData); });
  monitor->AddObserver(vtkVolumeCutNerveMonitor::LevelChangedEvent, counter);
  const double burr = 1.0;
  int lastLevel = vtkVolumeCutNerveMonitor::NotReady;
  int changes = 0;
  const double steps[] = { 6.0, 5.0, 3.9, 3.0, 2.1, 1.9, 1.5, 1.1, 0.9, 0.5, 0.1, -0.1, -0.3 };
  for (double distance : steps)
  {
    const double p[3] = { centre[0] + 1.0 + burr + distance, centre[1], centre[2] };
    monitor->UpdateWithBurr(p, burr);
    changes += monitor->GetLevel(0) != lastLevel ? 1 : 0;
    lastLevel = monitor->GetLevel(0);
    CHECK_INT(monitor->GetLevel(0), monitor->GetLevelOfDistance(distance));
  }
  CHECK_INT(lastLevel, vtkVolumeCutNerveMonitor::Contact);
  CHECK_INT(changes, 5); // not ready -> silent -> sparse clicks -> bursts -> continuous -> contact
  CHECK_INT(levelEvents, changes);
  CHECK_INT(monitor->GetNumberOfLevelChanges(), changes);
  CHECK_INT(monitor->GetHighestLevel(), vtkVolumeCutNerveMonitor::Contact);
  // Beyond the range: a lower bound, silent.
  const double far[3] = { centre[0] + 40.0, centre[1], centre[2] };
  Reading reading;
  monitor->Measure(far, 1.0, &reading, 1);
  CHECK_BOOL(reading.Distance >= monitor->GetRange() - 1.0, true);
  CHECK_INT(reading.Level, vtkVolumeCutNerveMonitor::Silent);
  return EXIT_SUCCESS;
}

int TestBadInput()
{
  vtkNew<vtkVolumeCutNerveMonitor> monitor;
  const double spacing[3] = { 0.5, 0.5, 0.5 };
  const int dims[3] = { 20, 20, 20 };
  Grid grid(dims, spacing, 0.0);
  auto empty = grid.Rasterise([](const double*) { return false; }, 1);
  auto some = grid.Rasterise([](const double*) { return true; }, 1);

  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_INT(monitor->AddStructure("facial nerve", some, 1), -1); // no geometry yet
  TESTING_OUTPUT_ASSERT_ERRORS_END();

  // Skewed axes (a gantry tilt) are refused; a turned orthogonal grid is not.
  vtkNew<vtkMatrix4x4> sheared;
  sheared->DeepCopy(grid.IJKToRAS);
  sheared->SetElement(0, 2, 0.2);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(monitor->SetGeometry(dims, sheared), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(monitor->SetGeometry(dims, grid.IJKToRAS), true);

  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_INT(monitor->AddStructure("chorda tympani", empty, 1), -1);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  // A structure outside the scan: its voxels lie beyond the anatomy's.
  auto outside = grid.Rasterise([](const double*) { return true; }, 1);
  outside->SetExtent(40, 59, 0, 19, 0, 19);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_INT(monitor->AddStructure("sigmoid sinus", outside, 1), -1);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_INT(monitor->GetNumberOfStructures(), 0);

  CHECK_INT(monitor->AddStructure("facial nerve", some, 1), 0);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_INT(monitor->AddStructure("facial nerve", some, 1), -1); // name used
  TESTING_OUTPUT_ASSERT_ERRORS_END();

  // Thresholds out of order: refused, the old ones kept.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(monitor->SetThresholds(2.0, 4.0, 1.0), false);
  CHECK_BOOL(monitor->SetThresholds(4.0, 2.0, 0.0), false);
  CHECK_BOOL(monitor->SetThresholds(4.0, 2.0, 2.0), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_DOUBLE(monitor->GetSilentThreshold(), 4.0);
  CHECK_DOUBLE(monitor->GetSparseThreshold(), 2.0);
  CHECK_DOUBLE(monitor->GetBurstThreshold(), 1.0);

  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(monitor->PrepareTool(nullptr), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  Reading reading;
  CHECK_INT(monitor->MeasureTool(grid.IJKToRAS->GetData(), &reading, 1), -1);

  std::ostringstream printed;
  monitor->Print(printed);
  CHECK_BOOL(printed.str().find("facial nerve") != std::string::npos, true);
  return EXIT_SUCCESS;
}

/// Processor time is what a query costs; its wall time adds whatever the
/// system did meanwhile (another process, a timer interrupt), which no code
/// of the monitor can remove. Sanitizers slow every access several times.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr double SanitizerSlowdown = 20.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
constexpr double SanitizerSlowdown = 20.0;
#else
constexpr double SanitizerSlowdown = 1.0;
#endif
#else
constexpr double SanitizerSlowdown = 1.0;
#endif

/// Build on a worker while another thread measures without waiting, each
/// answer from the fields ready then (the others not ready, said so); then
/// the cost of a query of 10 structures, the first after the build
/// included, in the querying thread's processor time.
int TestThreadsAndCost()
{
  const double spacing[3] = { 0.15, 0.15, 0.15 };
  const int dims[3] = { 64, 64, 48 };
  Grid grid(dims, spacing, 10.0);
  vtkNew<vtkVolumeCutNerveMonitor> monitor;
  monitor->SetRange(3.0);
  monitor->SetGeometry(grid.Dimensions, grid.IJKToRAS);
  double centre[3];
  grid.Centre(centre);
  std::vector<Cylinder> nerves;
  for (int n = 0; n < 10; ++n)
  {
    Cylinder nerve;
    const double angle = 2.0 * vtkMath::Pi() * n / 10.0;
    nerve.Point[0] = centre[0] + 2.5 * std::cos(angle);
    nerve.Point[1] = centre[1] + 2.5 * std::sin(angle);
    nerve.Point[2] = centre[2];
    nerve.Axis[0] = std::sin(angle);
    nerve.Axis[1] = 0.3;
    nerve.Axis[2] = std::cos(angle);
    vtkMath::Normalize(nerve.Axis);
    nerve.Radius = 0.3 + 0.05 * n;
    nerves.push_back(nerve);
    auto labels = grid.Rasterise([&](const double* p) { return nerve.SurfaceDistance(p) <= 0.0; }, 1);
    CHECK_INT(monitor->AddStructure(("nerve " + std::to_string(n)).c_str(), labels, 1), n);
  }
  vtkNew<vtkPoints> probe;
  probe->InsertNextPoint(centre);
  vtkNew<vtkDoubleArray> distances, microseconds, processor;
  std::atomic<bool> done{ false };
  std::thread worker([&] {
    monitor->Build();
    done = true;
  });
  std::vector<std::vector<double>> whileBuilding;
  std::vector<double> processorWhileBuilding;
  while (!done)
  {
    monitor->MeasureAlong(probe, 1.0, distances, microseconds, processor);
    whileBuilding.emplace_back(distances->GetPointer(0), distances->GetPointer(0) + 10);
    processorWhileBuilding.push_back(processor->GetValue(0));
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  worker.join();
  CHECK_BOOL(monitor->IsBuilt(), true);
  // The first query once built: no field's memory is touched for the first
  // time, nothing is built lazily.
  monitor->MeasureAlong(probe, 1.0, distances, microseconds, processor);
  const double firstProcessor = processor->GetValue(0);
  const double firstWall = microseconds->GetValue(0);
  std::vector<double> built(distances->GetPointer(0), distances->GetPointer(0) + 10);
  std::cout << "10 fields built on a worker in " << monitor->GetLastBuildTime() << " s (longest "
            << monitor->GetLastMaximumStructureBuildTime() << " s), " << monitor->GetMemorySize() / 1048576.0 << " MiB; "
            << whileBuilding.size() << " measurements meanwhile; first query after: " << firstWall << " us (processor " << firstProcessor
            << " us)" << std::endl;
  // Meanwhile a structure read either not ready (NaN) or its final reading:
  // a query never saw a field half built, nor waited for one.
  int ready = 0;
  for (const std::vector<double>& readings : whileBuilding)
  {
    for (int n = 0; n < 10; ++n)
    {
      if (!std::isnan(readings[n]))
      {
        ++ready;
        CHECK_BOOL(readings[n] == built[n], true);
      }
    }
  }
  // A timer interrupt's handler counts in the processor time too (tens of
  // microseconds on a virtual machine, every few milliseconds), and a query
  // after another process ran finds the caches cold: a generous bound per
  // query, and a few allowed above the tick's budget.
  const double budget = 20.0 * SanitizerSlowdown;
  // A query that waited for a build would have its processor time in the
  // milliseconds every time; one in a hundred may meet another process's
  // cache storm under a parallel ctest.
  const auto slowWhileBuilding =
    std::count_if(processorWhileBuilding.begin(), processorWhileBuilding.end(), [&](double value) { return value > 50.0 * budget; });
  CHECK_BOOL(slowWhileBuilding <= 1 + static_cast<std::ptrdiff_t>(processorWhileBuilding.size() / 100), true);
  CHECK_BOOL(firstProcessor <= 50.0 * budget, true);

  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(10);
  const int queries = 5000;
  vtkNew<vtkPoints> positions;
  for (int n = 0; n < queries; ++n)
  {
    positions->InsertNextPoint(centre[0] + Random(random, -3.0, 3.0), centre[1] + Random(random, -3.0, 3.0), centre[2] + Random(random, -3.0, 3.0));
  }
  // A code stall (a lock, an allocation, something built lazily) shows in
  // every pass; a busy machine's in one: the best of three passes counts.
  bool withinBudget = false;
  for (int pass = 0; pass < 3 && !withinBudget; ++pass)
  {
    CHECK_BOOL(monitor->MeasureAlong(positions, 1.0, distances, microseconds, processor), true);
    std::vector<double> wall(queries), cost(queries);
    for (int n = 0; n < queries; ++n)
    {
      wall[n] = microseconds->GetValue(n);
      cost[n] = processor->GetValue(n);
    }
    const auto overBudget = std::count_if(cost.begin(), cost.end(), [&](double value) { return value > budget; });
    std::sort(wall.begin(), wall.end());
    std::sort(cost.begin(), cost.end());
    std::cout << "query of 10 structures (burr), pass " << pass + 1 << ": p50 " << wall[queries / 2] << " us, p99 " << wall[queries * 99 / 100]
              << " us, max " << wall.back() << " us; processor time p50 " << cost[queries / 2] << " us, p99 " << cost[queries * 99 / 100]
              << " us, max " << cost.back() << " us, " << overBudget << " above " << budget << " us; " << ready
              << " readings ready during the build" << std::endl;
    withinBudget = cost[queries * 99 / 100] <= budget && overBudget <= queries / 50;
  }
  CHECK_BOOL(withinBudget, true);
  return EXIT_SUCCESS;
}
}

int vtkVolumeCutNerveMonitorTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestLevelsAndEvents());
  CHECK_EXIT_SUCCESS(TestBadInput());
  CHECK_EXIT_SUCCESS(TestSphereAccuracyAndTools());
  CHECK_EXIT_SUCCESS(TestCylinderAccuracy());
  CHECK_EXIT_SUCCESS(TestThreadsAndCost());
  return EXIT_SUCCESS;
}
