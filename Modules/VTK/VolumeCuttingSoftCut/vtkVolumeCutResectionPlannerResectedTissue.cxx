// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// vtkVolumeCutResectionPlanner::BuildResectedTissueFunction: the tissue a
// depth of cut removes as an implicit function, whose contour is the
// resection's mesh (measured by vtkVolumeCutResectionEstimate).
#include "vtkVolumeCutResectionPlannerInternals.h"
#include "vtkVolumeCutDistanceTransform.h"
#include "vtkVolumeCutSoftCutThreads.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include <cmath>
#include <limits>

using namespace vtkVolumeCutSoftCut;

//------------------------------------------------------------------------------
bool vtkVolumeCutResectionPlanner::BuildResectedTissueFunction(double depth, int subdivision, vtkImageData* function)
{
  if (!function || (subdivision != 1 && subdivision != 2))
  {
    return this->Fail("BuildResectedTissueFunction: give an image and a subdivision of 1 or 2");
  }
  vtkNew<vtkImageData> distances;
  vtkNew<vtkImageData> keep;
  if (!this->BuildRegion(depth, distances, keep))
  {
    return false;
  }
  const int* extent = distances->GetExtent();
  const int size[3] = { extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1 };
  const double margin = 2.0 * this->Impl->Grid.MaxSpacing();
  const double unit = this->Impl->Grid.MinSpacing();
  // The kept voxels' cubes as a distance (voxel units, scaled by the
  // smallest spacing): exact half-way between a kept voxel and its neighbour.
  std::vector<float> kept(static_cast<size_t>(size[0]) * size[1] * size[2]);
  {
    std::vector<unsigned char> sites(kept.size());
    const unsigned char* keepValues = static_cast<unsigned char*>(keep->GetScalarPointer());
    std::copy(keepValues, keepValues + kept.size(), sites.begin());
    const double unitSpacing[3] = { 1.0, 1.0, 1.0 };
    vtkVolumeCutDistanceTransform::Compute(size, unitSpacing, sites.data(), kept.data(), nullptr);
    for (size_t id = 0; id < kept.size(); ++id)
    {
      kept[id] = sites[id] ? static_cast<float>(0.5 * unit) : static_cast<float>(unit * (0.5 - std::sqrt(kept[id])));
    }
  }
  const float* region = static_cast<float*>(distances->GetScalarPointer());
  // The region's components with the skin itself (-depth) for the air
  // margin's, and the kept cubes.
  auto component = [&](int a, int b, int c, int which) -> float {
    const size_t id = (static_cast<size_t>(c) * size[1] + b) * size[0] + a;
    if (which == RegionComponents)
    {
      return kept[id];
    }
    const float value = region[RegionComponents * id + which];
    return which == 2 ? static_cast<float>(value + margin) : value;
  };
  // One sample of padding, positive, closes the surface at the image's faces.
  const int s = subdivision;
  const int samples[3] = { (size[0] - 1) * s + 3, (size[1] - 1) * s + 3, (size[2] - 1) * s + 3 };
  function->Initialize();
  function->SetDimensions(const_cast<int*>(samples));
  function->SetSpacing(1.0 / s, 1.0 / s, 1.0 / s);
  function->SetOrigin(extent[0] - 1.0 / s, extent[2] - 1.0 / s, extent[4] - 1.0 / s);
  vtkNew<vtkFloatArray> values;
  values->SetName("ResectedTissue");
  values->SetNumberOfTuples(static_cast<vtkIdType>(samples[0]) * samples[1] * samples[2]);
  function->GetPointData()->SetScalars(values);
  float* out = values->GetPointer(0);
  vtkVolumeCutSoftCutThreads::For(0, samples[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType qz = begin; qz < end; ++qz)
    {
      for (int qy = 0; qy < samples[1]; ++qy)
      {
        for (int qx = 0; qx < samples[0]; ++qx)
        {
          const int q[3] = { qx, qy, static_cast<int>(qz) };
          float& target = out[(static_cast<size_t>(qz) * samples[1] + qy) * samples[0] + qx];
          if (q[0] == 0 || q[1] == 0 || q[2] == 0 || q[0] == samples[0] - 1 || q[1] == samples[1] - 1 || q[2] == samples[2] - 1)
          {
            target = static_cast<float>(unit);
            continue;
          }
          int base[3];
          double f[3];
          for (int a = 0; a < 3; ++a)
          {
            const int local = q[a] - 1;
            base[a] = std::min(local / s, size[a] - 2 >= 0 ? size[a] - 2 : 0);
            f[a] = size[a] > 1 ? double(local) / s - base[a] : 0.0;
          }
          float result = -std::numeric_limits<float>::infinity();
          for (int which = 0; which <= RegionComponents; ++which)
          {
            double value = 0.0;
            for (int corner = 0; corner < 8; ++corner)
            {
              const int d[3] = { corner & 1, (corner >> 1) & 1, (corner >> 2) & 1 };
              const double w = (d[0] ? f[0] : 1.0 - f[0]) * (d[1] ? f[1] : 1.0 - f[1]) * (d[2] ? f[2] : 1.0 - f[2]);
              if (w != 0.0)
              {
                value += w * component(std::min(size[0] - 1, base[0] + d[0]), std::min(size[1] - 1, base[1] + d[1]), std::min(size[2] - 1, base[2] + d[2]), which);
              }
            }
            result = std::max(result, static_cast<float>(value));
          }
          target = result;
        }
      }
    }
  });
  return true;
}
