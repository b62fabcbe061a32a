// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// The CPU reference of adaptive multivolume ray casting against exact depths:
// a cube of bone (faces through voxel centres, a two-voxel ramp) with a
// spherical pit cut into its top face, seen from above in parallel projection.
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutRayCaster.h"

#include <vtkAddonTestingMacros.h>

#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace
{
constexpr int N = 40;
constexpr double Spacing = 0.5;
constexpr double Center = 20 * Spacing; // voxel 20
constexpr double Half = 10 * Spacing;   // faces through voxels 10 and 30
constexpr double CameraZ = 100.0;
constexpr double Near = 50.0;
constexpr double Far = 150.0;
constexpr double ViewHalfWidth = 8.0;
constexpr int Pixels = 64;

void MakeCube(vtkImageData* image)
{
  image->SetDimensions(N, N, N);
  image->AllocateScalars(VTK_FLOAT, 1);
  float* values = static_cast<float*>(image->GetScalarPointer());
  for (int k = 0; k < N; ++k)
  {
    for (int j = 0; j < N; ++j)
    {
      for (int i = 0; i < N; ++i)
      {
        const double q[3] = { std::abs(i * Spacing - Center) - Half, std::abs(j * Spacing - Center) - Half,
          std::abs(k * Spacing - Center) - Half };
        const double outside =
          std::sqrt(std::pow(std::max(q[0], 0.0), 2) + std::pow(std::max(q[1], 0.0), 2) + std::pow(std::max(q[2], 0.0), 2));
        const double distance = outside + std::min(std::max({ q[0], q[1], q[2] }), 0.0);
        values[(k * N + j) * N + i] = static_cast<float>(1000.0 * std::min(1.0, std::max(0.0, 0.5 - distance / (2.0 * Spacing))));
      }
    }
  }
}

// Parallel projection looking down -z from (Center, Center, CameraZ).
void MakeCamera(vtkMatrix4x4* worldToNDC)
{
  worldToNDC->Identity();
  worldToNDC->SetElement(0, 0, 1.0 / ViewHalfWidth);
  worldToNDC->SetElement(0, 3, -Center / ViewHalfWidth);
  worldToNDC->SetElement(1, 1, 1.0 / ViewHalfWidth);
  worldToNDC->SetElement(1, 3, -Center / ViewHalfWidth);
  worldToNDC->SetElement(2, 2, -2.0 / (Far - Near));
  worldToNDC->SetElement(2, 3, 2.0 * (CameraZ - Near) / (Far - Near) - 1.0);
}

double WorldZ(float depth)
{
  return CameraZ - (Near + depth * (Far - Near));
}

double PixelCoordinate(int pixel)
{
  return Center + ((pixel + 0.5) / Pixels * 2.0 - 1.0) * ViewHalfWidth;
}
}

int vtkVolumeCutRayCasterTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkNew<vtkImageData> ct;
  MakeCube(ct);
  vtkNew<vtkMatrix4x4> ijkToRas;
  for (int axis = 0; axis < 3; ++axis)
  {
    ijkToRas->SetElement(axis, axis, Spacing);
  }
  const int dims[3] = { N, N, N };
  vtkNew<vtkVolumeCutField> cut;
  CHECK_BOOL(cut->Initialize(dims, ijkToRas, 2), true);
  const double top = Center + Half;
  const double pit[3] = { Center + 0.13, Center - 0.07, top };
  const double radius = 2.2;
  CHECK_BOOL(cut->CutCapsule(pit, pit, radius), true);

  vtkNew<vtkVolumeCutRayCaster> caster;
  caster->SetAnatomy(ct, ijkToRas);
  caster->SetIsoValue(500.0);
  caster->AddCutField(cut);
  vtkNew<vtkMatrix4x4> camera;
  MakeCamera(camera);
  CHECK_BOOL(caster->Render(camera, Pixels, Pixels), true);
  CHECK_INT(static_cast<int>(caster->GetNumberOfRaysCast()), Pixels * Pixels);

  // Every pixel against the exact scene: depth of the pit's sphere, of the
  // top face, or nothing.
  double worst = 0.0;
  const float* depth = caster->GetDepthBuffer();
  const int* source = caster->GetSourceBuffer();
  for (int y = 0; y < Pixels; ++y)
  {
    for (int x = 0; x < Pixels; ++x)
    {
      const double px = PixelCoordinate(x);
      const double py = PixelCoordinate(y);
      const bool overCube = std::abs(px - Center) < Half && std::abs(py - Center) < Half;
      const double r2 = (px - pit[0]) * (px - pit[0]) + (py - pit[1]) * (py - pit[1]);
      const int p = y * Pixels + x;
      if (!overCube)
      {
        // Pixels within a pixel of the cube's side faces may go either way.
        if (std::abs(std::abs(px - Center) - Half) > 0.25 && std::abs(std::abs(py - Center) - Half) > 0.25 && depth[p] < 1.f)
        {
          std::cerr << "pixel " << x << "," << y << " outside the cube shows a surface" << std::endl;
          return EXIT_FAILURE;
        }
        continue;
      }
      const bool inPit = r2 < radius * radius;
      const double exact = inPit ? pit[2] - std::sqrt(radius * radius - r2) : top;
      if (std::abs(std::sqrt(r2) - radius) < 0.05)
      {
        continue; // the pit's rim, where the view grazes the sphere
      }
      worst = std::max(worst, std::abs(WorldZ(depth[p]) - exact));
      const int expectedSource = inPit ? vtkVolumeCutRayCaster::SourceCutField : vtkVolumeCutRayCaster::SourceObject;
      if (source[p] != expectedSource)
      {
        std::cerr << "pixel " << x << "," << y << ": source " << source[p] << ", expected " << expectedSource << std::endl;
        return EXIT_FAILURE;
      }
    }
  }
  std::cout << "largest depth error: " << worst << " mm" << std::endl;
  if (worst > 0.01)
  {
    std::cerr << "depth error " << worst << " mm exceeds 0.01 mm" << std::endl;
    return EXIT_FAILURE;
  }

  // The pit's normal at the middle pixel: towards the sphere's centre.
  const int middle = Pixels / 2;
  const float* normal = caster->GetNormalBuffer() + 3 * (middle * Pixels + middle);
  const double px = PixelCoordinate(middle);
  const double dx = pit[0] - px;
  const double dy = pit[1] - px;
  const double exactNormal[3] = { dx / radius, dy / radius, std::sqrt(radius * radius - dx * dx - dy * dy) / radius };
  const double cosine = normal[0] * exactNormal[0] + normal[1] * exactNormal[1] + normal[2] * exactNormal[2];
  if (cosine < std::cos(0.5 * 3.14159265358979 / 180.0))
  {
    std::cerr << "pit normal " << normal[0] << " " << normal[1] << " " << normal[2] << " vs " << exactNormal[0] << " "
              << exactNormal[1] << " " << exactNormal[2] << std::endl;
    return EXIT_FAILURE;
  }

  // Cutting more recasts only the pixels over modified bricks.
  const double more[3] = { Center - 3.0, Center - 3.0, top };
  CHECK_BOOL(cut->CutCapsule(more, more, 0.5), true);
  CHECK_BOOL(caster->Render(camera, Pixels, Pixels), true);
  CHECK_BOOL(caster->GetLastRenderWasLocalized(), true);
  if (caster->GetNumberOfRaysCast() <= 0 || caster->GetNumberOfRaysCast() > Pixels * Pixels / 4)
  {
    std::cerr << "localized update cast " << caster->GetNumberOfRaysCast() << " rays" << std::endl;
    return EXIT_FAILURE;
  }

  // A cut field on another grid: an error, and the anatomy alone is drawn.
  const int otherDims[3] = { N + 2, N, N };
  vtkNew<vtkVolumeCutField> other;
  CHECK_BOOL(other->Initialize(otherDims, ijkToRas, 2), true);
  CHECK_BOOL(other->CutCapsule(pit, pit, radius), true);
  vtkNew<vtkVolumeCutRayCaster> mismatched;
  mismatched->SetAnatomy(ct, ijkToRas);
  mismatched->SetIsoValue(500.0);
  mismatched->AddCutField(other);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(mismatched->Render(camera, Pixels, Pixels), true);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  const double centerDepth = WorldZ(mismatched->GetDepthBuffer()[middle * Pixels + middle]);
  if (std::abs(centerDepth - top) > 0.01)
  {
    std::cerr << "without its cut the top face should show, got z " << centerDepth << std::endl;
    return EXIT_FAILURE;
  }
  return EXIT_SUCCESS;
}
