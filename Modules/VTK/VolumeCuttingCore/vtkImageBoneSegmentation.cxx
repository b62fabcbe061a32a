// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkImageBoneSegmentation.h"

#include "vtkArrayDispatch.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkImageData.h"
#include "vtkImageGaussianSmooth.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkImageBoneSegmentation);

namespace
{
/// Copies the first component into floats, the working type of the growing.
struct CopyToFloat
{
  template <typename ArrayT>
  void operator()(ArrayT* array, std::vector<float>& values) const
  {
    const auto tuples = vtk::DataArrayTupleRange(array);
    values.resize(static_cast<size_t>(tuples.size()));
    size_t index = 0;
    for (const auto tuple : tuples)
    {
      values[index++] = static_cast<float>(tuple[0]);
    }
  }
};
} // namespace

//------------------------------------------------------------------------------
vtkImageBoneSegmentation::vtkImageBoneSegmentation() = default;

//------------------------------------------------------------------------------
vtkImageBoneSegmentation::~vtkImageBoneSegmentation() = default;

//------------------------------------------------------------------------------
int vtkImageBoneSegmentation::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkDataObject::SetPointDataActiveScalarInfo(outputVector->GetInformationObject(0), VTK_UNSIGNED_CHAR, 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkImageBoneSegmentation::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  this->NumberOfCorticalVoxels = 0;
  this->NumberOfTrabecularVoxels = 0;
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkImageData* output = vtkImageData::GetData(outputVector);
  vtkDataArray* scalars = input ? input->GetPointData()->GetScalars() : nullptr;
  if (!scalars || scalars->GetNumberOfTuples() == 0)
  {
    vtkErrorMacro("RequestData: the input image has no voxel values");
    return 0;
  }
  if (!(this->TrabecularThreshold <= this->CorticalThreshold) || !std::isfinite(this->TrabecularThreshold) || !std::isfinite(this->CorticalThreshold))
  {
    vtkErrorMacro("RequestData: thresholds must be finite and the trabecular threshold (" << this->TrabecularThreshold
                                                                                           << ") must not exceed the cortical threshold ("
                                                                                           << this->CorticalThreshold << ")");
    return 0;
  }

  int extent[6];
  input->GetExtent(extent);
  output->SetExtent(extent);
  output->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  vtkUnsignedCharArray* labelArray = vtkUnsignedCharArray::SafeDownCast(output->GetPointData()->GetScalars());
  labelArray->SetName("BoneLabels");
  labelArray->FillValue(BackgroundLabel);

  std::vector<float> values;
  if (this->SmoothingStandardDeviation > 0.0)
  {
    double spacing[3];
    input->GetSpacing(spacing);
    vtkNew<vtkImageData> floatInput;
    floatInput->ShallowCopy(input);
    vtkNew<vtkImageGaussianSmooth> smooth;
    smooth->SetInputData(floatInput);
    smooth->SetDimensionality(3);
    smooth->SetStandardDeviations(this->SmoothingStandardDeviation / spacing[0], this->SmoothingStandardDeviation / spacing[1],
      this->SmoothingStandardDeviation / spacing[2]);
    smooth->SetRadiusFactors(3.0, 3.0, 3.0);
    smooth->Update();
    scalars = smooth->GetOutput()->GetPointData()->GetScalars();
    if (!vtkArrayDispatch::Dispatch::Execute(scalars, CopyToFloat{}, values))
    {
      CopyToFloat{}(scalars, values);
    }
  }
  else if (!vtkArrayDispatch::Dispatch::Execute(scalars, CopyToFloat{}, values))
  {
    CopyToFloat{}(scalars, values);
  }

  const vtkIdType dims[3] = { extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1 };
  const vtkIdType sliceSize = dims[0] * dims[1];
  const vtkIdType voxelCount = sliceSize * dims[2];
  unsigned char* labels = labelArray->GetPointer(0);
  const float cortical = static_cast<float>(this->CorticalThreshold);
  const float trabecular = static_cast<float>(this->TrabecularThreshold);

  // A vector with a moving head is the FIFO queue: no per-element allocation,
  // and memory bounded by the number of bone voxels.
  std::vector<vtkIdType> queue;
  for (vtkIdType index = 0; index < voxelCount; ++index)
  {
    if (values[index] >= cortical) // false for NaN
    {
      labels[index] = CorticalLabel;
      queue.push_back(index);
    }
  }
  this->NumberOfCorticalVoxels = static_cast<vtkIdType>(queue.size());

  const vtkIdType progressInterval = std::max<vtkIdType>(voxelCount / 20, 1);
  for (size_t head = 0; head < queue.size(); ++head)
  {
    if (static_cast<vtkIdType>(head) % progressInterval == 0)
    {
      this->UpdateProgress(std::min(1.0, static_cast<double>(head) / static_cast<double>(voxelCount)));
      if (this->CheckAbort())
      {
        break;
      }
    }
    const vtkIdType index = queue[head];
    const vtkIdType k = index / sliceSize;
    const vtkIdType j = (index - k * sliceSize) / dims[0];
    const vtkIdType i = index - k * sliceSize - j * dims[0];
    const vtkIdType neighbors[6] = { i > 0 ? index - 1 : -1, i + 1 < dims[0] ? index + 1 : -1, j > 0 ? index - dims[0] : -1,
      j + 1 < dims[1] ? index + dims[0] : -1, k > 0 ? index - sliceSize : -1, k + 1 < dims[2] ? index + sliceSize : -1 };
    for (vtkIdType neighbor : neighbors)
    {
      if (neighbor >= 0 && labels[neighbor] == BackgroundLabel && values[neighbor] >= trabecular)
      {
        labels[neighbor] = TrabecularLabel;
        queue.push_back(neighbor);
        ++this->NumberOfTrabecularVoxels;
      }
    }
  }
  if (this->BoundaryIsCortical)
  {
    // The partial-volume shell of the cortex, cortex by the paper's model:
    // grown voxels on the ramp from the cortex (a cortical face neighbour)
    // out to what is not bone. The shell is one or two voxels thick: its
    // outer voxels touch the outside and the cortex, or a grown voxel of
    // higher value that touches the cortex; its inner voxels touch the
    // cortex and an outer voxel of lower value. Grown bone away from the
    // cortex (septa between air cells) stays trabecular.
    auto faceNeighbors = [&](vtkIdType index, vtkIdType neighbors[6]) {
      const vtkIdType k = index / sliceSize;
      const vtkIdType j = (index - k * sliceSize) / dims[0];
      const vtkIdType i = index - k * sliceSize - j * dims[0];
      neighbors[0] = i > 0 ? index - 1 : -1;
      neighbors[1] = i + 1 < dims[0] ? index + 1 : -1;
      neighbors[2] = j > 0 ? index - dims[0] : -1;
      neighbors[3] = j + 1 < dims[1] ? index + dims[0] : -1;
      neighbors[4] = k > 0 ? index - sliceSize : -1;
      neighbors[5] = k + 1 < dims[2] ? index + sliceSize : -1;
    };
    auto touches = [&](vtkIdType index, auto&& predicate) {
      vtkIdType neighbors[6];
      faceNeighbors(index, neighbors);
      return std::any_of(neighbors, neighbors + 6, [&](vtkIdType n) { return n >= 0 && predicate(n); });
    };
    const size_t firstGrown = static_cast<size_t>(this->NumberOfCorticalVoxels);
    std::vector<unsigned char> state(static_cast<size_t>(voxelCount), 0); // 1: touches the cortex, 2: outer shell
    for (size_t head = firstGrown; head < queue.size(); ++head)
    {
      state[queue[head]] = touches(queue[head], [&](vtkIdType n) { return labels[n] == CorticalLabel; }) ? 1 : 0;
    }
    std::vector<vtkIdType> outer;
    for (size_t head = firstGrown; head < queue.size(); ++head)
    {
      const vtkIdType index = queue[head];
      if (touches(index, [&](vtkIdType n) { return labels[n] == BackgroundLabel; }) &&
        (state[index] == 1 || touches(index, [&](vtkIdType n) { return state[n] == 1 && values[n] > values[index]; })))
      {
        outer.push_back(index);
      }
    }
    for (vtkIdType index : outer)
    {
      state[index] = 2;
    }
    std::vector<vtkIdType> shell = outer;
    for (size_t head = firstGrown; head < queue.size(); ++head)
    {
      const vtkIdType index = queue[head];
      if (state[index] == 1 && touches(index, [&](vtkIdType n) { return state[n] == 2 && values[n] < values[index]; }))
      {
        shell.push_back(index);
      }
    }
    for (vtkIdType index : shell)
    {
      labels[index] = CorticalLabel;
    }
    this->NumberOfCorticalVoxels += static_cast<vtkIdType>(shell.size());
    this->NumberOfTrabecularVoxels -= static_cast<vtkIdType>(shell.size());
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkImageBoneSegmentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "CorticalThreshold: " << this->CorticalThreshold << "\n";
  os << indent << "TrabecularThreshold: " << this->TrabecularThreshold << "\n";
  os << indent << "SmoothingStandardDeviation: " << this->SmoothingStandardDeviation << "\n";
  os << indent << "BoundaryIsCortical: " << this->BoundaryIsCortical << "\n";
  os << indent << "NumberOfCorticalVoxels: " << this->NumberOfCorticalVoxels << "\n";
  os << indent << "NumberOfTrabecularVoxels: " << this->NumberOfTrabecularVoxels << "\n";
}
