// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingCore (not installed, not wrapped): the shield of one
// brick, as vtkVolumeCutProtection builds it and vtkVolumeCutField's writer
// merges tools with it.
#ifndef vtkVolumeCutProtectionBrick_h
#define vtkVolumeCutProtectionBrick_h

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutProtection.h"

#include <cstdint>

struct vtkVolumeCutProtection::Brick
{
  static constexpr int Samples = vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize;
  /// Signed distance to the shielded structures' (smoothed) surface, field quanta, negative inside; negative in every shielded voxel.
  int16_t Distance[Samples];
  /// The structure a sample lies in, or the nearest one outside.
  uint8_t Label[Samples];
};

#endif
