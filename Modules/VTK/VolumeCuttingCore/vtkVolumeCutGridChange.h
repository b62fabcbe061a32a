// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutGridChange
 * @brief   What differs between a cut field's grid and an anatomy's voxel grid.
 *
 * A cut saved with a scene is read back onto an anatomy that a reader may
 * have reindexed, resampled or moved. The cut is kept bit for bit when only
 * rounding differs, and resampled (with a message naming the change) when the
 * grid really changed; this class tells the two apart. Grids are compared to
 * a thousandth of a voxel: the field's anatomy grid is rebuilt from its
 * sub-voxel grid, whose voxel 0 sits (0.5 / f - 0.5) anatomy voxels from
 * anatomy voxel 0 at sub-voxel factor f.
 */

#ifndef vtkVolumeCutGridChange_h
#define vtkVolumeCutGridChange_h

#include "vtkObject.h"
#include "vtkVolumeCuttingCoreExport.h" // For export macro

#include <string> // For the description

class vtkMatrix4x4;
class vtkVolumeCutField;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutGridChange : public vtkObject
{
public:
  static vtkVolumeCutGridChange* New();
  vtkTypeMacro(vtkVolumeCutGridChange, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * What differs between the field's grid and an anatomy grid (dimensions and
   * IJK-to-RAS) cut at a sub-voxel factor, as "; "-separated parts (sub-voxel
   * factor, dimensions, voxel spacing or axes, origin); "" when nothing does,
   * "the cut field is empty" for a field without a grid.
   */
  static std::string Describe(vtkVolumeCutField* field, const int anatomyDimensions[3], vtkMatrix4x4* anatomyIJKToRAS, int subVoxelFactor);

protected:
  vtkVolumeCutGridChange();
  ~vtkVolumeCutGridChange() override;

private:
  vtkVolumeCutGridChange(const vtkVolumeCutGridChange&) = delete;
  void operator=(const vtkVolumeCutGridChange&) = delete;
};

#endif
