// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutAnatomySampler.h"
#include "vtkVolumeCutSoftCutThreads.h"

#include "vtkDataArray.h"

#include <cmath>

using namespace vtkVolumeCutSoftCut;

namespace
{
template <typename T>
void CopyBox(const T* data, const int dims[3], const int box[6], float* out)
{
  const int size[3] = { box[1] - box[0] + 1, box[3] - box[2] + 1, box[5] - box[4] + 1 };
  vtkVolumeCutSoftCutThreads::For(0, size[2], [&](vtkIdType begin, vtkIdType end) {
    for (vtkIdType c = begin; c < end; ++c)
    {
      for (int b = 0; b < size[1]; ++b)
      {
        const T* row = data + ((static_cast<vtkIdType>(box[4] + c) * dims[1] + box[2] + b) * dims[0] + box[0]);
        float* target = out + (static_cast<vtkIdType>(c) * size[1] + b) * size[0];
        for (int a = 0; a < size[0]; ++a)
        {
          target[a] = static_cast<float>(row[a]);
        }
      }
    }
  });
}
} // namespace

//------------------------------------------------------------------------------
void vtkVolumeCutAnatomySampler::ForgetCache()
{
  this->LocalBox[0] = this->LocalBox[2] = this->LocalBox[4] = 0;
  this->LocalBox[1] = this->LocalBox[3] = this->LocalBox[5] = -1;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutAnatomySampler::CacheVoxels(const int box[6])
{
  this->ForgetCache();
  int clipped[6];
  std::copy(box, box + 6, clipped);
  std::vector<float> values;
  if (!this->CopyVoxels(clipped, values))
  {
    return false;
  }
  this->Local.swap(values);
  std::copy(clipped, clipped + 6, this->LocalBox);
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutAnatomySampler::CopyVoxels(int box[6], std::vector<float>& out) const
{
  for (int a = 0; a < 3; ++a)
  {
    box[2 * a] = std::max(0, box[2 * a]);
    box[2 * a + 1] = std::min(this->Dims[a] - 1, box[2 * a + 1]);
    if (box[2 * a + 1] < box[2 * a])
    {
      out.clear();
      return true;
    }
  }
  out.resize(static_cast<size_t>(box[1] - box[0] + 1) * (box[3] - box[2] + 1) * (box[5] - box[4] + 1));
  if (this->Scalars->GetNumberOfComponents() == 1)
  {
    switch (this->Scalars->GetDataType())
    {
      vtkTemplateMacro(CopyBox(static_cast<const VTK_TT*>(this->Scalars->GetVoidPointer(0)), this->Dims, box, out.data()));
      default:
        return false;
    }
    return true;
  }
  size_t index = 0;
  for (int k = box[4]; k <= box[5]; ++k)
  {
    for (int j = box[2]; j <= box[3]; ++j)
    {
      for (int i = box[0]; i <= box[1]; ++i)
      {
        out[index++] = static_cast<float>(this->Scalars->GetComponent((static_cast<vtkIdType>(k) * this->Dims[1] + j) * this->Dims[0] + i, 0));
      }
    }
  }
  return true;
}

//------------------------------------------------------------------------------
Vec vtkVolumeCutAnatomySampler::Gradient(const Vec& x) const
{
  Vec g;
  for (int axis = 0; axis < 3; ++axis)
  {
    Vec a = x;
    Vec b = x;
    a[axis] += this->Spacing[axis];
    b[axis] -= this->Spacing[axis];
    g[axis] = (this->Sample(a) - this->Sample(b)) / (2.0 * this->Spacing[axis]);
  }
  return g;
}

//------------------------------------------------------------------------------
Vec vtkVolumeCutAnatomySampler::BoxGradient(const Vec& x, int r) const
{
  const double h = this->MaxSpacing();
  Vec g{ 0.0, 0.0, 0.0 };
  for (int axis = 0; axis < 3; ++axis)
  {
    const int b = (axis + 1) % 3;
    const int c = (axis + 2) % 3;
    double sum = 0.0;
    for (int ob = -r; ob <= r; ++ob)
    {
      for (int oc = -r; oc <= r; ++oc)
      {
        Vec y = x;
        y[b] += ob * h;
        y[c] += oc * h;
        for (int layer : { r, r + 1 })
        {
          Vec up = y;
          Vec down = y;
          up[axis] += layer * h;
          down[axis] -= layer * h;
          sum += this->Sample(up) - this->Sample(down);
        }
      }
    }
    g[axis] = sum;
  }
  return g;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutAnatomySampler::FindCrossing(const Vec& x, const Vec& direction, double reach, double iso, Vec& found) const
{
  const double step = 0.25 * this->MinSpacing();
  const double v0 = this->Sample(x) - iso;
  if (v0 == 0.0)
  {
    found = x;
    return true;
  }
  for (double t = step; t <= reach + 1e-9; t += step)
  {
    for (double sign : { 1.0, -1.0 })
    {
      const Vec y = Add(x, Scale(direction, sign * t));
      const double v = this->Sample(y) - iso;
      if ((v > 0.0) != (v0 > 0.0) || v == 0.0)
      {
        // Bisection between the last two samples.
        double lo = sign * (t - step);
        double hi = sign * t;
        double vLo = this->Sample(Add(x, Scale(direction, lo))) - iso;
        for (int iteration = 0; iteration < 30; ++iteration)
        {
          const double mid = 0.5 * (lo + hi);
          const double vMid = this->Sample(Add(x, Scale(direction, mid))) - iso;
          if ((vMid > 0.0) == (vLo > 0.0))
          {
            lo = mid;
            vLo = vMid;
          }
          else
          {
            hi = mid;
          }
        }
        found = Add(x, Scale(direction, 0.5 * (lo + hi)));
        return true;
      }
    }
  }
  return false;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutAnatomySampler::ToSkin(const Vec& x, double reach, double iso, Vec& onSkin) const
{
  Vec direction = Normalized(this->Gradient(x));
  if (Norm(direction) == 0.0)
  {
    return false;
  }
  return this->FindCrossing(x, direction, reach, iso, onSkin);
}
