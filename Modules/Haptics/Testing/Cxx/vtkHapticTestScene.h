// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Shared by the haptics tests: an analytic scene whose surface is known
// exactly. The CT grows linearly with depth below a plane, so its trilinear
// interpolation (linear functions are reproduced exactly) crosses the
// iso-value exactly on the plane; the grid is anisotropic-free but flipped
// in x, as reoriented scans are.
#ifndef vtkHapticTestScene_h
#define vtkHapticTestScene_h

#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkVolumeCutField.h>

#include <functional>

struct vtkHapticTestScene
{
  /// Voxel edge (mm), the plane's height (RAS z, mm), the iso-value.
  double Spacing = 0.5;
  double PlaneHeight = 0.3;
  double IsoValue = 300.0;
  int Size = 49;
  vtkNew<vtkImageData> CT;
  vtkNew<vtkMatrix4x4> IJKToRAS;
  vtkNew<vtkVolumeCutField> Field;

  vtkHapticTestScene()
  {
    // RAS x = 12 - 0.5 i (flipped), y = -12 + 0.5 j, z = -12 + 0.5 k.
    const double half = 0.5 * (this->Size - 1) * this->Spacing;
    this->IJKToRAS->SetElement(0, 0, -this->Spacing);
    this->IJKToRAS->SetElement(1, 1, this->Spacing);
    this->IJKToRAS->SetElement(2, 2, this->Spacing);
    this->IJKToRAS->SetElement(0, 3, half);
    this->IJKToRAS->SetElement(1, 3, -half);
    this->IJKToRAS->SetElement(2, 3, -half);
    this->CT->SetDimensions(this->Size, this->Size, this->Size);
    vtkNew<vtkFloatArray> values;
    values->SetNumberOfValues(static_cast<vtkIdType>(this->Size) * this->Size * this->Size);
    vtkIdType n = 0;
    for (int k = 0; k < this->Size; ++k)
    {
      const double z = -half + k * this->Spacing;
      for (int j = 0; j < this->Size; ++j)
      {
        for (int i = 0; i < this->Size; ++i)
        {
          values->SetValue(n++, static_cast<float>(this->IsoValue + 1000.0 * (this->PlaneHeight - z)));
        }
      }
    }
    this->CT->GetPointData()->SetScalars(values);
    const int dims[3] = { this->Size, this->Size, this->Size };
    this->Field->Initialize(dims, this->IJKToRAS, 2);
  }

  /// A label image on the scene's grid: 1 where inside(RAS) holds, else 0. Returns how many voxels are labelled.
  vtkIdType MakeLabels(vtkImageData* labels, const std::function<bool(const double ras[3])>& inside) const
  {
    labels->SetDimensions(this->Size, this->Size, this->Size);
    labels->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
    vtkIdType count = 0;
    this->ForEachVoxel([&](int i, int j, int k, const double ras[3]) {
      const bool in = inside(ras);
      *static_cast<unsigned char*>(labels->GetScalarPointer(i, j, k)) = in ? 1 : 0;
      count += in ? 1 : 0;
    });
    return count;
  }

  /// Labelled voxels whose centre a field shows removed (its signed distance there not positive).
  int CountRemovedLabelled(vtkImageData* labels, vtkVolumeCutField* field) const
  {
    int removed = 0;
    this->ForEachVoxel([&](int i, int j, int k, const double ras[3]) {
      if (*static_cast<unsigned char*>(labels->GetScalarPointer(i, j, k)) != 0)
      {
        removed += field->GetSignedDistance(ras) > 0.0 ? 0 : 1;
      }
    });
    return removed;
  }

  void ForEachVoxel(const std::function<void(int, int, int, const double[3])>& visit) const
  {
    for (int k = 0; k < this->Size; ++k)
    {
      for (int j = 0; j < this->Size; ++j)
      {
        for (int i = 0; i < this->Size; ++i)
        {
          const double ijk[4] = { double(i), double(j), double(k), 1.0 };
          double ras[4];
          this->IJKToRAS->MultiplyPoint(ijk, ras);
          visit(i, j, k, ras);
        }
      }
    }
  }
};

#endif
