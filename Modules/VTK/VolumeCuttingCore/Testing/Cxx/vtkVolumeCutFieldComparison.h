// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Tests' helper: two fields on the same lattice compared sample by sample.
#ifndef vtkVolumeCutFieldComparison_h
#define vtkVolumeCutFieldComparison_h

#include "vtkVolumeCutField.h"

#include <algorithm>
#include <cstdlib>
#include <vector>

/// The largest difference (quanta) between the fields' samples, and how many differ.
inline void CompareFieldSamples(vtkVolumeCutField* first, vtkVolumeCutField* second, int& worst, long& differing)
{
  const int* brickDims = first->GetBrickDimensions();
  const vtkIdType count = static_cast<vtkIdType>(brickDims[0]) * brickDims[1] * brickDims[2];
  const int samples = vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize;
  std::vector<short> a(samples), b(samples);
  worst = 0;
  differing = 0;
  for (vtkIdType id = 0; id < count; ++id)
  {
    first->CopyBrick(id, a.data());
    second->CopyBrick(id, b.data());
    for (int n = 0; n < samples; ++n)
    {
      worst = std::max(worst, std::abs(a[n] - b[n]));
      differing += a[n] != b[n] ? 1 : 0;
    }
  }
}

#endif
