// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutPartialVolumeLabels.h"

#include "vtkVolumeCutParallelFor.h"

#include <cmath>
#include <limits>

//------------------------------------------------------------------------------
void vtkVolumeCutPartialVolumeLabels::Resolve(const std::vector<uint16_t>& labels, const std::vector<float>& values, const int dims[3],
  const std::vector<vtkVolumeCutRayScene::SegmentStyle>& styles, int maximumThreads, std::vector<uint16_t>& resolved)
{
  resolved = labels;
  const vtkIdType count = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  if (labels.size() != static_cast<size_t>(count) || values.size() != static_cast<size_t>(count))
  {
    return;
  }
  // Per label: the iso-value of a shown iso segment, NaN for the others
  // (hidden: no appearance or no opacity; or drawn by its own shape).
  std::vector<float> iso(styles.size(), std::numeric_limits<float>::quiet_NaN());
  std::vector<char> hidden(styles.size(), 1);
  float minimumIso = std::numeric_limits<float>::infinity();
  for (size_t label = 1; label < styles.size(); ++label)
  {
    const vtkVolumeCutRayScene::SegmentStyle& style = styles[label];
    hidden[label] = !(style.Opacity > 0.f);
    if (!hidden[label] && !style.Shape)
    {
      iso[label] = style.Iso;
      minimumIso = std::min(minimumIso, style.Iso);
    }
  }
  if (!std::isfinite(minimumIso))
  {
    return; // no iso segment shown: no surface to keep whole
  }
  // The 26 directions, faces first: where several shown segments qualify,
  // the nearest one wins, and every path decides the same way.
  int offsets[26][3];
  int directions = 0;
  for (int order = 1; order <= 3; ++order)
  {
    for (int dk = -1; dk <= 1; ++dk)
    {
      for (int dj = -1; dj <= 1; ++dj)
      {
        for (int di = -1; di <= 1; ++di)
        {
          if (std::abs(di) + std::abs(dj) + std::abs(dk) == order)
          {
            offsets[directions][0] = di;
            offsets[directions][1] = dj;
            offsets[directions][2] = dk;
            ++directions;
          }
        }
      }
    }
  }
  const vtkIdType sy = dims[0];
  const vtkIdType sz = static_cast<vtkIdType>(dims[0]) * dims[1];
  auto isHidden = [&](int label) { return label == 0 || label >= static_cast<int>(styles.size()) || hidden[label]; };
  vtkVolumeCutParallelFor(maximumThreads, dims[2], [&](vtkIdType beginZ, vtkIdType endZ) {
    for (vtkIdType k = beginZ; k < endZ; ++k)
    {
      for (int j = 0; j < dims[1]; ++j)
      {
        for (int i = 0; i < dims[0]; ++i)
        {
          const vtkIdType voxel = i + j * sy + k * sz;
          const int label = labels[voxel];
          if (!isHidden(label))
          {
            continue;
          }
          const float value = values[voxel];
          if (!(value >= minimumIso))
          {
            resolved[voxel] = 0;
            continue;
          }
          for (int d = 0; d < directions; ++d)
          {
            const int* o = offsets[d];
            const int ni = i + o[0], nj = j + o[1], nk = static_cast<int>(k) + o[2];
            const int fi = i - o[0], fj = j - o[1], fk = static_cast<int>(k) - o[2];
            if (ni < 0 || nj < 0 || nk < 0 || ni >= dims[0] || nj >= dims[1] || nk >= dims[2] || fi < 0 || fj < 0 || fk < 0 ||
              fi >= dims[0] || fj >= dims[1] || fk >= dims[2])
            {
              continue;
            }
            const vtkIdType near = ni + nj * sy + nk * sz;
            const int owner = labels[near];
            if (isHidden(owner) || std::isnan(iso[owner]))
            {
              continue;
            }
            const float level = iso[owner];
            if (value >= level && values[near] >= value && values[fi + fj * sy + fk * sz] < level)
            {
              resolved[voxel] = static_cast<uint16_t>(owner);
              break;
            }
          }
        }
      }
    }
  });
}
