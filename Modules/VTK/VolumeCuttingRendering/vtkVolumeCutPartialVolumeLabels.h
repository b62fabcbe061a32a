// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutPartialVolumeLabels
 * @brief   The label map the rays read: partial-volume voxels given to the shown segment whose material fills them.
 *
 * A label map classifies voxel centres, but the CT averages each voxel's
 * material: along a shown segment drawn at a CT iso-value, the first voxel
 * outside it (soft tissue, air, a hidden segment or no label at all) is
 * often above the iso-value because part of the bone lies in it. Such a
 * voxel, competing as material that no shown segment claims, or any hidden
 * voxel competing as its own segment, puts the bone's border where the label
 * weights are equal, half a voxel from the bone's last voxel whatever the
 * CT says: the iso-surface is cut flat there and the bone shows the voxels'
 * terraces, with a ring wherever the iso-surface leaves the border.
 * Here, before any ray is cast:
 *  - a hidden or unlabelled voxel above a shown iso segment's value that lies
 *    between that segment's voxel, at least as bright, and a voxel below its
 *    value on the opposite side (along one of the 26 directions) takes the
 *    segment's label: its brightness is the segment's partial volume;
 *  - any other hidden voxel below every shown iso-value becomes unlabelled
 *    (it cannot be visible, and should not cut the CT's surface either).
 * Shown segments' voxels, and hidden ones above the iso-value that are not a
 * partial-volume rim (a hidden bone next to a shown one), keep their label,
 * so borders between segments stay where the label map puts them.
 */
#ifndef vtkVolumeCutPartialVolumeLabels_h
#define vtkVolumeCutPartialVolumeLabels_h

#include "vtkVolumeCutRayScene.h"

#include <cstdint>
#include <vector>

class vtkVolumeCutPartialVolumeLabels
{
public:
  /**
   * \a labels (the label map as given) resolved as described above against
   * \a values (the CT, both on the grid of \a dims voxels) and \a styles (per
   * label; labels beyond it are hidden) into \a resolved.
   */
  static void Resolve(const std::vector<uint16_t>& labels, const std::vector<float>& values, const int dims[3],
    const std::vector<vtkVolumeCutRayScene::SegmentStyle>& styles, int maximumThreads, std::vector<uint16_t>& resolved);
};

#endif
