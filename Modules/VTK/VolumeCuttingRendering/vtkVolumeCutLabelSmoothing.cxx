// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutLabelSmoothing.h"

#include "vtkVolumeCutLabelSurface.h"
#include "vtkVolumeCutParallelFor.h"

#include <algorithm>

//------------------------------------------------------------------------------
void vtkVolumeCutLabelSmoothing::Smooth(const std::vector<uint16_t>& labelMap, const int dims[3], const double spacing[3],
  const std::vector<int>& labels, double sigma, int maximumThreads, std::vector<vtkVolumeCutRayScene::FractionVolume>& fractions)
{
  if (labels.empty() || !(sigma >= 0.0) || labelMap.empty())
  {
    return;
  }
  // The surface is vtkVolumeCutLabelSurface's (the nerve monitor measures to
  // the same one); the fraction is a linear ramp of its levels, 0.5 on it,
  // so that the trilinear interpolation of fractions interpolates them.
  std::vector<std::vector<int>> boxes;
  vtkVolumeCutLabelSurface::ComputeLabelBoxes(labelMap.data(), dims, labels, boxes);
  for (size_t n = 0; n < labels.size(); ++n)
  {
    const int* labelBox = boxes[n].data();
    vtkVolumeCutLabelSurface::Levels levels;
    if (!vtkVolumeCutLabelSurface::Initialize(dims, spacing, labelBox, sigma, levels))
    {
      continue; // not in the label map
    }
    vtkVolumeCutParallelFor(maximumThreads, vtkVolumeCutLabelSurface::GetNumberOfSlices(labelBox, levels), [&](vtkIdType begin, vtkIdType end) {
      vtkVolumeCutLabelSurface::ComputeSlices(labelMap.data(), dims, spacing, labels[n], labelBox, sigma, static_cast<int>(begin),
        static_cast<int>(end), levels);
    });
    vtkVolumeCutLabelSurface::ExtrapolateEnds(labelBox, levels);
    vtkVolumeCutRayScene::FractionVolume fraction;
    fraction.Label = labels[n];
    fraction.Values.assign(static_cast<size_t>(dims[0]) * dims[1] * dims[2], 0.f);
    const int* box = levels.Box;
    const double toFraction = 1.0 / (2.0 * levels.Ramp);
    const float* level = levels.Values.data();
    for (int k = box[4]; k <= box[5]; ++k)
    {
      for (int j = box[2]; j <= box[3]; ++j)
      {
        float* row = fraction.Values.data() + dims[0] * (j + static_cast<size_t>(dims[1]) * k);
        for (int i = box[0]; i <= box[1]; ++i, ++level)
        {
          row[i] = static_cast<float>(0.5 - *level * toFraction);
        }
      }
    }
    fractions.push_back(std::move(fraction));
  }
}
