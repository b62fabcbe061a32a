// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkBinaryVoxelCutter
 * @brief   Whole-voxel cutting, the way open drilling simulators remove bone.
 *
 * A dense mask at the anatomy's resolution: a stroke removes every voxel whose
 * centre lies in the swept capsule. It is kept as the baseline that the
 * benchmarks and accuracy reports measure vtkVolumeCutField against (same
 * grid, same strokes, same process); the product does not cut with it.
 */

#ifndef vtkBinaryVoxelCutter_h
#define vtkBinaryVoxelCutter_h

#include "vtkObject.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <vector> // For the mask

class vtkMatrix4x4;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkBinaryVoxelCutter : public vtkObject
{
public:
  static vtkBinaryVoxelCutter* New();
  vtkTypeMacro(vtkBinaryVoxelCutter, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Allocate an empty mask for the anatomy grid; false (and an error) for
  /// non-positive dimensions or a non-invertible matrix.
  bool Initialize(const int dimensions[3], vtkMatrix4x4* ijkToRAS);

  /// Remove the voxels whose centres lie within radius (mm) of segment p0-p1.
  bool CutCapsule(const double p0[3], const double p1[3], double radius);

  /// Removed voxels times the voxel volume (mm^3).
  double ComputeRemovedVolume() const;

  /// Whether the voxel whose centre is nearest this RAS point is removed.
  bool IsRemoved(const double ras[3]) const;

protected:
  vtkBinaryVoxelCutter();
  ~vtkBinaryVoxelCutter() override;

  int Dimensions[3] = { 0, 0, 0 };
  double IJKToRAS[4][4];
  double RASToIJK[4][4];
  std::vector<unsigned char> Mask;

private:
  vtkBinaryVoxelCutter(const vtkBinaryVoxelCutter&) = delete;
  void operator=(const vtkBinaryVoxelCutter&) = delete;
};

#endif
