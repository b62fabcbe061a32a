// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutSceneInputs
 * @brief   How vtkVolumeCutRayCaster's inputs become the scene its rays read (vtkVolumeCutRayScene).
 *
 * The CT becomes floats with its grid's matrices, the label map shorts, each
 * fractional labelmap fractions 0..1 with the blocks where they are above 0,
 * the transfer functions tables and the clip planes plane equations; a cut
 * field is shown only where it was made on the anatomy's voxel grid. The ray
 * caster decides when each is copied again (PrepareScene).
 */
#ifndef vtkVolumeCutSceneInputs_h
#define vtkVolumeCutSceneInputs_h

#include "vtkVolumeCutRayScene.h"

#include <cstdint>
#include <vector>

class vtkColorTransferFunction;
class vtkDataArray;
class vtkImageData;
class vtkMatrix4x4;
class vtkPiecewiseFunction;
class vtkPlaneCollection;
class vtkVolumeCutField;

class vtkVolumeCutSceneInputs
{
public:
  /**
   * Copy the anatomy's grid (\a ijkToWorld, its inverse and the matrix that
   * turns IJK gradients into world normals), dimensions and first component
   * of \a scalars as floats into \a scene. Returns nullptr, or why it cannot
   * (the matrix is not invertible: nothing copied; the scalar type is not
   * supported).
   */
  static const char* CopyAnatomy(vtkImageData* anatomy, vtkDataArray* scalars, vtkMatrix4x4* ijkToWorld, vtkVolumeCutRayScene& scene);

  /// Copy the labels, clamped to 0..65535 (NaN: 0); returns whether any was out of that range.
  static bool CopyLabels(vtkDataArray* labels, std::vector<uint16_t>& copy);

  /// Map a fractional labelmap linearly from valueAtZero..valueAtOne to 0..1, clamped (NaN: 0).
  static void CopyFraction(vtkDataArray* values, double valueAtZero, double valueAtOne, std::vector<float>& fractions);

  /// Which fraction blocks of the scene's grid hold a corner where \a fraction is above 0.
  static void MarkNonZeroBlocks(const vtkVolumeCutRayScene& scene, vtkVolumeCutRayScene::FractionVolume& fraction, int maximumThreads);

  /// Whether two images have the same dimensions (a label map or fraction on the anatomy's grid).
  static bool SameDimensions(vtkImageData* a, vtkImageData* b);

  /**
   * Whether \a field was made on the voxel grid of an anatomy of \a dims
   * voxels placed by \a ijkToWorld (row-major): dimensions f times the
   * anatomy's for its sub-voxel factor f, and sub-voxel s at anatomy index
   * (s + 0.5) / f - 0.5 (within 1e-4 voxel).
   */
  static bool OnAnatomyGrid(vtkVolumeCutField* field, const int dims[3], const double ijkToWorld[16]);

  /// The transfer functions as tables over the union of their ranges (composite mode).
  static void CopyTransferFunctions(vtkColorTransferFunction* color, vtkPiecewiseFunction* opacity, vtkVolumeCutRayScene& scene);

  /// The planes' equations, normals of unit length; planes without a normal are left out.
  static void CopyPlanes(vtkPlaneCollection* planes, std::vector<vtkVolumeCutRayScene::PlaneEquation>& equations);
};

#endif
