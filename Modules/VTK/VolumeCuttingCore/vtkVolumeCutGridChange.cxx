// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutGridChange.h"
#include "vtkVolumeCutField.h"

#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

vtkStandardNewMacro(vtkVolumeCutGridChange);

//------------------------------------------------------------------------------
vtkVolumeCutGridChange::vtkVolumeCutGridChange() = default;

//------------------------------------------------------------------------------
vtkVolumeCutGridChange::~vtkVolumeCutGridChange() = default;

//------------------------------------------------------------------------------
std::string vtkVolumeCutGridChange::Describe(vtkVolumeCutField* field, const int anatomyDimensions[3], vtkMatrix4x4* anatomyIJKToRAS, int subVoxelFactor)
{
  std::ostringstream change;
  const int fieldFactor = field->GetSubVoxelFactor();
  if (fieldFactor < 1)
  {
    return "the cut field is empty";
  }
  if (fieldFactor != subVoxelFactor)
  {
    change << "sub-voxel factor " << fieldFactor << " -> " << subVoxelFactor << "; ";
  }
  const int* fieldDimensions = field->GetDimensions();
  if (fieldDimensions[0] != anatomyDimensions[0] * fieldFactor || fieldDimensions[1] != anatomyDimensions[1] * fieldFactor ||
    fieldDimensions[2] != anatomyDimensions[2] * fieldFactor)
  {
    change << "dimensions " << fieldDimensions[0] / fieldFactor << "x" << fieldDimensions[1] / fieldFactor << "x" << fieldDimensions[2] / fieldFactor
           << " -> " << anatomyDimensions[0] << "x" << anatomyDimensions[1] << "x" << anatomyDimensions[2] << "; ";
  }
  // The field's anatomy grid, rebuilt from its sub-voxel grid.
  vtkNew<vtkMatrix4x4> subToRas;
  field->GetSubVoxelIJKToRAS(subToRas);
  double spacing = std::numeric_limits<double>::max();
  bool axesDiffer = false;
  for (int axis = 0; axis < 3; ++axis)
  {
    double length2 = 0.0;
    double difference2 = 0.0;
    for (int row = 0; row < 3; ++row)
    {
      const double a = anatomyIJKToRAS->GetElement(row, axis);
      const double d = subToRas->GetElement(row, axis) * fieldFactor - a;
      length2 += a * a;
      difference2 += d * d;
    }
    spacing = std::min(spacing, std::sqrt(length2));
    axesDiffer |= !(difference2 <= 1e-6 * length2);
  }
  if (axesDiffer)
  {
    change << "voxel spacing or axes; ";
  }
  double shift2 = 0.0;
  for (int row = 0; row < 3; ++row)
  {
    double expected = anatomyIJKToRAS->GetElement(row, 3);
    for (int axis = 0; axis < 3; ++axis)
    {
      expected += anatomyIJKToRAS->GetElement(row, axis) * (0.5 / fieldFactor - 0.5);
    }
    const double d = subToRas->GetElement(row, 3) - expected;
    shift2 += d * d;
  }
  if (!(std::sqrt(shift2) <= 1e-3 * spacing))
  {
    change << "origin moved by " << std::sqrt(shift2) << " mm; ";
  }
  std::string text = change.str();
  return text.empty() ? text : text.substr(0, text.size() - 2);
}

//------------------------------------------------------------------------------
void vtkVolumeCutGridChange::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
}
