// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutDistanceTransform.h"

#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkVolumeCutSoftCutThreads.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutDistanceTransform);

namespace
{
constexpr float Infinity = std::numeric_limits<float>::infinity();
/// Lines processed together in the passes along y and z: 16 floats are one
/// cache line, so each line of the tile reads what its neighbours load.
constexpr int TileWidth = 16;

/// Scratch of one thread: a tile of lines and the envelope of one line.
struct Scratch
{
  std::vector<float> Values;
  std::vector<int> Features;
  std::vector<float> OutValues;
  std::vector<int> OutFeatures;
  std::vector<int> Parabolas;
  std::vector<double> Bounds;
  std::vector<double> Roots;
  std::vector<double> Inverse;
  void Reserve(int length, double s2)
  {
    this->Roots.resize(length);
    this->Inverse.resize(length);
    for (int d = 1; d < length; ++d)
    {
      this->Inverse[d] = 1.0 / (2.0 * s2 * d);
    }
    this->Values.resize(static_cast<size_t>(TileWidth) * length);
    this->Features.resize(static_cast<size_t>(TileWidth) * length);
    this->OutValues.resize(static_cast<size_t>(TileWidth) * length);
    this->OutFeatures.resize(static_cast<size_t>(TileWidth) * length);
    this->Parabolas.resize(length);
    this->Bounds.resize(static_cast<size_t>(length) + 1);
  }
};

/**
 * One line of a pass along an axis of spacing s: out[x] = min_q f[q] + (s (x - q))^2
 * and the feature of the minimising q; the lower envelope of the parabolas
 * rooted at the finite f[q], in one sweep to build it and one to read it.
 * inverse[d] is 1 / (2 s^2 d): the crossings divide by nothing.
 */
void EnvelopeLine(const float* f, const int* features, int n, double s2, const double* inverse, int* parabolas, double* bounds, double* roots,
  float* out, int* outFeatures)
{
  int k = -1;
  for (int q = 0; q < n; ++q)
  {
    if (!(f[q] < Infinity))
    {
      continue;
    }
    const double rootQ = f[q] + s2 * double(q) * double(q);
    if (k < 0)
    {
      k = 0;
      parabolas[0] = q;
      roots[0] = rootQ;
      bounds[0] = -std::numeric_limits<double>::infinity();
      bounds[1] = std::numeric_limits<double>::infinity();
      continue;
    }
    double crossing;
    for (;;)
    {
      // Where parabola q starts to lie below the last one of the envelope;
      // bounds[0] is -infinity, so the loop stops at k = 0.
      crossing = (rootQ - roots[k]) * inverse[q - parabolas[k]];
      if (crossing > bounds[k])
      {
        break;
      }
      --k;
    }
    ++k;
    parabolas[k] = q;
    roots[k] = rootQ;
    bounds[k] = crossing;
    bounds[k + 1] = std::numeric_limits<double>::infinity();
  }
  if (k < 0)
  {
    std::fill(out, out + n, Infinity);
    std::fill(outFeatures, outFeatures + n, -1);
    return;
  }
  int segment = 0;
  for (int x = 0; x < n; ++x)
  {
    while (bounds[segment + 1] < x)
    {
      ++segment;
    }
    const int p = parabolas[segment];
    const double dx = double(x - p);
    out[x] = static_cast<float>(s2 * dx * dx + f[p]);
    outFeatures[x] = features[p];
  }
}

/// The pass along x from binary sites: the nearer of the nearest site on each side.
void RowPass(const int dims[3], double sx, const unsigned char* sites, float* distances, int* features)
{
  const vtkIdType rows = static_cast<vtkIdType>(dims[1]) * dims[2];
  const int nx = dims[0];
  const double s2 = sx * sx;
  vtkVolumeCutSoftCutThreads::For(0, rows, [&](vtkIdType begin, vtkIdType end) {
    std::vector<int> left(nx);
    for (vtkIdType row = begin; row < end; ++row)
    {
      const vtkIdType offset = row * nx;
      const unsigned char* rowSites = sites + offset;
      int last = -1;
      for (int x = 0; x < nx; ++x)
      {
        if (rowSites[x])
        {
          last = x;
        }
        left[x] = last;
      }
      int next = -1;
      for (int x = nx - 1; x >= 0; --x)
      {
        if (rowSites[x])
        {
          next = x;
        }
        int nearest = left[x];
        if (next >= 0 && (nearest < 0 || next - x < x - nearest))
        {
          nearest = next;
        }
        if (nearest < 0)
        {
          distances[offset + x] = Infinity;
          features[offset + x] = -1;
        }
        else
        {
          const double dx = double(x - nearest);
          distances[offset + x] = static_cast<float>(s2 * dx * dx);
          features[offset + x] = static_cast<int>(offset + nearest);
        }
      }
    }
  });
}

/**
 * The pass along y (axis 1) or z (axis 2): lines of `length` samples
 * `stride` apart, gathered TileWidth neighbouring lines (consecutive x) at a
 * time.
 */
void ColumnPass(const int dims[3], int axis, double spacing, float* distances, int* features)
{
  const int nx = dims[0];
  const int length = dims[axis];
  const vtkIdType stride = axis == 1 ? nx : static_cast<vtkIdType>(nx) * dims[1];
  // Lines are indexed by (x, other) with other = z for the y pass, y for the z pass.
  const int others = axis == 1 ? dims[2] : dims[1];
  const vtkIdType otherStride = axis == 1 ? static_cast<vtkIdType>(nx) * dims[1] : nx;
  const int tilesPerRow = (nx + TileWidth - 1) / TileWidth;
  const double s2 = spacing * spacing;
  vtkVolumeCutSoftCutThreads::For(0, static_cast<vtkIdType>(tilesPerRow) * others, [&](vtkIdType begin, vtkIdType end) {
    Scratch scratch;
    scratch.Reserve(length, s2);
    for (vtkIdType tile = begin; tile < end; ++tile)
    {
      const int x0 = static_cast<int>(tile % tilesPerRow) * TileWidth;
      const int width = std::min(TileWidth, nx - x0);
      const vtkIdType first = (tile / tilesPerRow) * otherStride + x0;
      bool anySite[TileWidth] = {};
      for (int j = 0; j < length; ++j)
      {
        const vtkIdType index = first + j * stride;
        for (int t = 0; t < width; ++t)
        {
          const float value = distances[index + t];
          scratch.Values[t * length + j] = value;
          scratch.Features[t * length + j] = features[index + t];
          anySite[t] |= value < Infinity;
        }
      }
      bool anyLine = false;
      for (int t = 0; t < width; ++t)
      {
        if (anySite[t])
        {
          anyLine = true;
          EnvelopeLine(&scratch.Values[t * length], &scratch.Features[t * length], length, s2, scratch.Inverse.data(), scratch.Parabolas.data(),
            scratch.Bounds.data(), scratch.Roots.data(), &scratch.OutValues[t * length], &scratch.OutFeatures[t * length]);
        }
      }
      if (!anyLine)
      {
        continue; // nothing reached these lines yet: they stay infinite
      }
      for (int j = 0; j < length; ++j)
      {
        const vtkIdType index = first + j * stride;
        for (int t = 0; t < width; ++t)
        {
          if (anySite[t])
          {
            distances[index + t] = scratch.OutValues[t * length + j];
            features[index + t] = scratch.OutFeatures[t * length + j];
          }
        }
      }
    }
  });
}
} // namespace

//------------------------------------------------------------------------------
vtkVolumeCutDistanceTransform::vtkVolumeCutDistanceTransform() = default;

//------------------------------------------------------------------------------
vtkVolumeCutDistanceTransform::~vtkVolumeCutDistanceTransform() = default;

//------------------------------------------------------------------------------
void vtkVolumeCutDistanceTransform::Compute(
  const int dimensions[3], const double spacing[3], const unsigned char* sites, float* squaredDistances, int* nearestSites)
{
  const vtkIdType count = static_cast<vtkIdType>(dimensions[0]) * dimensions[1] * dimensions[2];
  if (count <= 0)
  {
    return;
  }
  // The passes carry the features whether or not the caller wants them.
  std::vector<int> ownFeatures;
  int* features = nearestSites;
  if (!features)
  {
    ownFeatures.resize(static_cast<size_t>(count));
    features = ownFeatures.data();
  }
  RowPass(dimensions, spacing[0], sites, squaredDistances, features);
  if (dimensions[1] > 1)
  {
    ColumnPass(dimensions, 1, spacing[1], squaredDistances, features);
  }
  if (dimensions[2] > 1)
  {
    ColumnPass(dimensions, 2, spacing[2], squaredDistances, features);
  }
}

//------------------------------------------------------------------------------
int vtkVolumeCutDistanceTransform::RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkDataObject::SetPointDataActiveScalarInfo(outputVector->GetInformationObject(0), VTK_FLOAT, 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkVolumeCutDistanceTransform::RequestData(vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkImageData* output = vtkImageData::GetData(outputVector);
  vtkDataArray* scalars = input ? input->GetPointData()->GetScalars() : nullptr;
  if (!scalars)
  {
    vtkErrorMacro("RequestData: the input image has no scalars to take the sites from");
    return 0;
  }
  output->SetExtent(input->GetExtent());
  output->SetOrigin(input->GetOrigin());
  output->SetSpacing(input->GetSpacing());
  output->SetDirectionMatrix(input->GetDirectionMatrix());
  int dims[3];
  input->GetDimensions(dims);
  const vtkIdType count = input->GetNumberOfPoints();
  std::vector<unsigned char> sites(static_cast<size_t>(count));
  for (vtkIdType id = 0; id < count; ++id)
  {
    sites[id] = scalars->GetComponent(id, 0) != 0.0;
  }
  double spacing[3];
  input->GetSpacing(spacing);
  for (double& s : spacing)
  {
    s = std::abs(s);
  }
  vtkNew<vtkFloatArray> distances;
  distances->SetName("Distance");
  distances->SetNumberOfValues(count);
  std::vector<int> nearest(static_cast<size_t>(count));
  Compute(dims, spacing, sites.data(), distances->GetPointer(0), nearest.data());
  if (!this->OutputSquaredDistance)
  {
    float* values = distances->GetPointer(0);
    vtkVolumeCutSoftCutThreads::For(0, count, [values](vtkIdType begin, vtkIdType end) {
      for (vtkIdType id = begin; id < end; ++id)
      {
        values[id] = std::sqrt(values[id]);
      }
    });
  }
  output->GetPointData()->SetScalars(distances);
  if (this->ComputeNearestSite)
  {
    vtkNew<vtkIdTypeArray> sitesArray;
    sitesArray->SetName("NearestSite");
    sitesArray->SetNumberOfValues(count);
    for (vtkIdType id = 0; id < count; ++id)
    {
      sitesArray->SetValue(id, nearest[id]);
    }
    output->GetPointData()->AddArray(sitesArray);
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkVolumeCutDistanceTransform::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "OutputSquaredDistance: " << this->OutputSquaredDistance << "\n";
  os << indent << "ComputeNearestSite: " << this->ComputeNearestSite << "\n";
}
