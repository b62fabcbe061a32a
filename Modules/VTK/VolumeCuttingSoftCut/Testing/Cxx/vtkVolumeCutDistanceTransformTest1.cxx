// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutDistanceTransform.h"

#include <vtkAddonTestingMacros.h>

#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkImageData.h>
#include <vtkImageEuclideanDistance.h>
#include <vtkMinimalStandardRandomSequence.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

#include <cmath>
#include <limits>
#include <vector>

namespace
{
double Distance2(const int a[3], const int b[3], const double spacing[3])
{
  double sum = 0.0;
  for (int axis = 0; axis < 3; ++axis)
  {
    const double d = (a[axis] - b[axis]) * spacing[axis];
    sum += d * d;
  }
  return sum;
}

void Unravel(vtkIdType id, const int dims[3], int ijk[3])
{
  ijk[0] = static_cast<int>(id % dims[0]);
  ijk[1] = static_cast<int>((id / dims[0]) % dims[1]);
  ijk[2] = static_cast<int>(id / (static_cast<vtkIdType>(dims[0]) * dims[1]));
}

/// Exact squared distances by brute force, and the nearest sites reported
/// at exactly that distance; on an anisotropic grid with sparse sites.
int TestAgainstBruteForce()
{
  const int dims[3] = { 23, 17, 13 };
  const double spacing[3] = { 0.7, 1.1, 1.6 };
  const vtkIdType count = dims[0] * dims[1] * dims[2];
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(7);
  std::vector<unsigned char> sites(count, 0);
  std::vector<vtkIdType> siteIds;
  for (vtkIdType id = 0; id < count; ++id)
  {
    random->Next();
    if (random->GetValue() < 0.004)
    {
      sites[id] = 1;
      siteIds.push_back(id);
    }
  }
  CHECK_BOOL(siteIds.size() > 3, true);
  std::vector<float> squared(count);
  std::vector<int> nearest(count);
  vtkVolumeCutDistanceTransform::Compute(dims, spacing, sites.data(), squared.data(), nearest.data());
  for (vtkIdType id = 0; id < count; ++id)
  {
    int p[3];
    Unravel(id, dims, p);
    double best = std::numeric_limits<double>::infinity();
    for (vtkIdType site : siteIds)
    {
      int q[3];
      Unravel(site, dims, q);
      best = std::min(best, Distance2(p, q, spacing));
    }
    if (std::abs(squared[id] - best) > 1e-4 * (1.0 + best))
    {
      std::cerr << "voxel " << id << ": squared distance " << squared[id] << ", brute force " << best << std::endl;
      return EXIT_FAILURE;
    }
    CHECK_BOOL(nearest[id] >= 0 && sites[nearest[id]] != 0, true);
    int q[3];
    Unravel(nearest[id], dims, q);
    if (std::abs(Distance2(p, q, spacing) - best) > 1e-4 * (1.0 + best))
    {
      std::cerr << "voxel " << id << ": its nearest site " << nearest[id] << " is not at the nearest distance" << std::endl;
      return EXIT_FAILURE;
    }
  }
  // No site at all: infinite everywhere, no nearest site.
  std::fill(sites.begin(), sites.end(), 0);
  vtkVolumeCutDistanceTransform::Compute(dims, spacing, sites.data(), squared.data(), nearest.data());
  CHECK_BOOL(std::isinf(squared[0]) && std::isinf(squared[count - 1]), true);
  CHECK_INT(nearest[count / 2], -1);
  return EXIT_SUCCESS;
}

/// The same distances as VTK's Saito transform (vtkImageEuclideanDistance),
/// through the algorithm's pipeline interface. With ConsiderAnisotropy,
/// VTK 9.6 weights only the z axis by its spacing (x and y count as 1), so
/// the grid compared has unit spacing in x and y (the brute-force test above
/// covers any spacing).
int TestAgainstVTK()
{
  const int dims[3] = { 40, 31, 27 };
  const double spacing[3] = { 1.0, 1.0, 1.5 };
  vtkNew<vtkImageData> sites;
  sites->SetDimensions(dims[0], dims[1], dims[2]);
  sites->SetSpacing(spacing[0], spacing[1], spacing[2]);
  sites->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  // The vtk transform measures the distance of nonzero voxels to zero ones.
  vtkNew<vtkImageData> objects;
  objects->SetDimensions(dims[0], dims[1], dims[2]);
  objects->SetSpacing(spacing[0], spacing[1], spacing[2]);
  objects->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        // A tilted line and a sphere's shell: the sites of a strip and a skin.
        const double x = i * spacing[0] - 18.0;
        const double y = j * spacing[1] - 14.0;
        const double z = k * spacing[2] - 20.0;
        const bool line = std::abs(x - 0.5 * y) < 0.5 && std::abs(z + 10.0) < 0.8;
        const bool shell = std::abs(std::sqrt(x * x + y * y + (z - 15.0) * (z - 15.0)) - 9.0) < 0.6;
        const unsigned char site = (line || shell) ? 1 : 0;
        *static_cast<unsigned char*>(sites->GetScalarPointer(i, j, k)) = site;
        *static_cast<unsigned char*>(objects->GetScalarPointer(i, j, k)) = site ? 0 : 1;
      }
    }
  }
  vtkNew<vtkVolumeCutDistanceTransform> transform;
  transform->SetInputData(sites);
  transform->OutputSquaredDistanceOn();
  transform->ComputeNearestSiteOn();
  transform->Update();
  vtkNew<vtkImageEuclideanDistance> reference;
  reference->SetInputData(objects);
  reference->ConsiderAnisotropyOn();
  reference->InitializeOn();
  reference->Update();
  vtkDataArray* ours = transform->GetOutput()->GetPointData()->GetScalars();
  vtkDataArray* theirs = reference->GetOutput()->GetPointData()->GetScalars();
  CHECK_NOT_NULL(transform->GetOutput()->GetPointData()->GetArray("NearestSite"));
  double worst = 0.0;
  for (vtkIdType id = 0; id < ours->GetNumberOfTuples(); ++id)
  {
    const double a = ours->GetComponent(id, 0);
    const double b = theirs->GetComponent(id, 0);
    worst = std::max(worst, std::abs(a - b) / (1.0 + b));
  }
  if (worst > 1e-5)
  {
    std::cerr << "vtkImageEuclideanDistance differs by a relative " << worst << std::endl;
    return EXIT_FAILURE;
  }
  // Distances (not squared) are the square roots.
  const double squared = ours->GetComponent(100, 0);
  transform->OutputSquaredDistanceOff();
  transform->Update();
  const double d = transform->GetOutput()->GetPointData()->GetScalars()->GetComponent(100, 0);
  CHECK_DOUBLE_TOLERANCE(d * d, squared, 1e-3);
  return EXIT_SUCCESS;
}
} // namespace

int vtkVolumeCutDistanceTransformTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestAgainstBruteForce());
  CHECK_EXIT_SUCCESS(TestAgainstVTK());
  return EXIT_SUCCESS;
}
