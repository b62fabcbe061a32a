// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutRemovedVoxels
 * @brief   The removed fraction of each anatomy voxel, kept up to date stroke by stroke.
 *
 * The removed volume per segment is shown live while the user drills. Its
 * source, the partial-volume fraction of every voxel the cut reaches, costs
 * tens of microseconds per voxel on the cut surface: recomputing the whole
 * cut after every stroke would grow with the session. This tally keeps the
 * fractions per brick of the field and recomputes only the bricks whose
 * samples, or their neighbours' (a fraction reads one brick further), changed
 * since the last update, by the field's brick stamps. A new shield (roles),
 * a new field or a new grid starts it over.
 */

#ifndef vtkVolumeCutRemovedVoxels_h
#define vtkVolumeCutRemovedVoxels_h

#include "vtkObject.h"
#include "vtkType.h"                    // For vtkTypeUInt64
#include "vtkVolumeCuttingCoreExport.h" // For export macro
#include "vtkWeakPointer.h"             // For the field

#include <unordered_map> // For the bricks
#include <utility>       // For std::pair
#include <vector>        // For the bricks

class vtkFloatArray;
class vtkIdTypeArray;
class vtkImageData;
class vtkVolumeCutField;

class VTK_VOLUMECUTTINGCORE_EXPORT vtkVolumeCutRemovedVoxels : public vtkObject
{
public:
  static vtkVolumeCutRemovedVoxels* New();
  vtkTypeMacro(vtkVolumeCutRemovedVoxels, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * Bring the tally up to date with the field (the same field as before, or
   * another one: then it starts over). Call it from a thread that may read
   * the field. Returns the number of bricks recomputed.
   */
  vtkIdType Update(vtkVolumeCutField* field);

  /// Anatomy voxels with a removed fraction above zero (linear IJK index) and their fractions.
  void GetVoxels(vtkIdTypeArray* anatomyVoxelIds, vtkFloatArray* fractions) const;
  vtkIdType GetNumberOfVoxels() const;
  /// Sum of the fractions (voxels); times the voxel volume, the removed volume.
  double GetTotalFraction() const;

  /**
   * The removed fraction of every anatomy voxel as a dense float image of the
   * anatomy's dimensions (IJK geometry, scalars named "RemovedFraction", 0
   * where nothing was removed): the fractional labelmap of the removed region.
   */
  void ExportFraction(const int anatomyDimensions[3], vtkImageData* fraction) const;

  /**
   * Blend each removed voxel of an anatomy image (its first component) towards
   * fillValue by the voxel's removed fraction: fully removed voxels take
   * fillValue, partly removed ones keep partial volume. Only the cut's voxels
   * are visited.
   */
  void BlendTowards(vtkImageData* anatomy, double fillValue) const;

#ifndef __VTK_WRAP__
  /// For each removed voxel: visit(anatomyVoxelId, fraction).
  template <typename Visitor>
  void ForEachVoxel(Visitor&& visit) const
  {
    for (const auto& brick : this->Bricks)
    {
      for (const auto& voxel : brick.second)
      {
        visit(voxel.first, voxel.second);
      }
    }
  }
#endif

protected:
  vtkVolumeCutRemovedVoxels();
  ~vtkVolumeCutRemovedVoxels() override;

  void Recompute(vtkIdType brickId);

  vtkWeakPointer<vtkVolumeCutField> Field;
  vtkMTimeType ShieldTime = 0;
  vtkTypeUInt64 Stamp = 0;
  std::unordered_map<vtkIdType, std::vector<std::pair<vtkIdType, float>>> Bricks;

private:
  vtkVolumeCutRemovedVoxels(const vtkVolumeCutRemovedVoxels&) = delete;
  void operator=(const vtkVolumeCutRemovedVoxels&) = delete;
};

#endif
