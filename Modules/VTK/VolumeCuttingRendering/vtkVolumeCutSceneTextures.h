// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutSceneTextures
 * @brief   The textures vtkVolumeCutOpenGLRayCaster's program reads, uploaded when what they hold changed.
 *
 * - the CT: R16 (value - minimum) where that loses nothing, else R32F;
 * - the labels: R8 or R16, else R32F; the fractions of up to four segments
 *   (one a channel): RGBA16, else RGBA32F; a 2^3 stand-in without them;
 * - the small tables: segment styles, the transfer function, the blocks'
 *   reach and gradient bound, the cells' bytes of vtkVolumeCutEmptySpace;
 * - each cut field's page table and brick atlas (vtkVolumeCutBrickAtlas);
 * - the depth of opaque geometry drawn before.
 * Each travels when what it holds changed: the CT with its values or grid,
 * labels and fractions with them, the small tables with anything, cut
 * fields brick by brick, the depth when its values differ.
 * NormalizedTextures off (normalized false) keeps every one float.
 */
#ifndef vtkVolumeCutSceneTextures_h
#define vtkVolumeCutSceneTextures_h

#include "vtkVolumeCutBrickAtlas.h"
#include "vtkVolumeCutOpenGLRayCaster.h"
#include "vtkVolumeCutRayCaster.h"

#include <vtkSmartPointer.h>
#include <vtkType.h>

#include <string>
#include <vector>

class vtkOpenGLRenderWindow;
class vtkShaderProgram;
class vtkTextureObject;
class vtkVolumeCutField;
class vtkWindow;

class vtkVolumeCutSceneTextures
{
public:
  vtkVolumeCutSceneTextures() = default;
  vtkVolumeCutSceneTextures(const vtkVolumeCutSceneTextures&) = delete;
  void operator=(const vtkVolumeCutSceneTextures&) = delete;

  /**
   * Upload what changed of the CT, labels, fractions and small tables of
   * \a view in window's context (current). False with GetErrorMessage() set
   * where a texture cannot be made.
   */
  bool UpdateScene(vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view, bool normalized);

  /**
   * Upload the bricks of \a fields modified since the last upload, field n
   * into GetBrickAtlas(n); \a uploaded counts them (those of fields before
   * a failure included). False with GetErrorMessage() set where a field's
   * textures cannot be made.
   */
  bool UpdateCutFields(
    vtkOpenGLRenderWindow* window, const std::vector<vtkVolumeCutField*>& fields, bool normalized, vtkIdType& uploaded);

  /**
   * Upload the depth of opaque geometry (width x height window depths;
   * nullptr: none, every ray runs to the far plane) if it differs from the
   * last upload. False with GetErrorMessage() set where it cannot be made.
   */
  bool UpdateOpaqueDepth(vtkOpenGLRenderWindow* window, const float* opaqueDepth, int width, int height);

  /// Why the last Update* returned false.
  const std::string& GetErrorMessage() const { return this->ErrorMessage; }

  /// Filter the CT and fractions by the texture unit (linear) or fetch them texel by texel.
  void SetFiltering(bool anatomyLinear, bool fractionsLinear);

  /**
   * Activate every texture the program of \a cutFields cut fields reads and
   * set its sampler uniform; \a active gets them, to deactivate after the draw.
   */
  void Activate(vtkShaderProgram* program, int cutFields, std::vector<vtkTextureObject*>& active);

  /// Release every texture and forget what they held.
  void Release(vtkWindow* window);

  /// GPU memory (bytes) of the textures.
  size_t GetMemorySize() const;

  /// Texels of all cut fields' brick atlases.
  vtkIdType GetCutAtlasTexels() const;

  const vtkVolumeCutBrickAtlas& GetBrickAtlas(int n) const { return this->BrickAtlases[n]; }

  /// Whether the CT is R16 (value - GetAnatomyMinimum()); the fractions RGBA16.
  bool GetAnatomyUnorm16() const { return this->AnatomyUnorm16; }
  bool GetFractionsUnorm16() const { return this->FractionsUnorm16; }
  float GetAnatomyMinimum() const { return this->AnatomyMinimum; }
  /// What turns a label texel back into the label (255, 65535, or 1 for floats).
  float GetLabelScale() const { return this->LabelScale; }
  /// Whether the cells' bytes are there for rays to walk through (iso-surface mode, exact R8).
  bool GetCellWalk() const { return this->CellWalk; }
  /// A count of the opaque depth's uploads: an image cast against another depth is stale.
  vtkTypeUInt64 GetOpaqueDepthVersion() const { return this->OpaqueDepthVersion; }

  ///@{
  /// Bytes a voxel as the driver stores it after the last upload (see vtkVolumeCutOpenGLRayCaster).
  int GetAnatomyBytesPerVoxel() const { return this->AnatomyBytesPerVoxel; }
  int GetLabelBytesPerVoxel() const { return this->LabelBytesPerVoxel; }
  int GetFractionBytesPerVoxel() const { return this->FractionBytesPerVoxel; }
  ///@}

private:
  bool UpdateAnatomy(vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view, bool normalized);
  bool UpdateLabels(vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view, bool normalized);
  bool UpdateTables(vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view);

  std::string ErrorMessage;
  vtkSmartPointer<vtkTextureObject> Anatomy;
  vtkSmartPointer<vtkTextureObject> Labels;
  vtkSmartPointer<vtkTextureObject> Fractions;
  vtkSmartPointer<vtkTextureObject> Styles;
  vtkSmartPointer<vtkTextureObject> Blocks;
  // Per 2 x 2 x 2 cells, a bit per cell that may hold a visible object
  // (vtkVolumeCutEmptySpace's bytes), and whether rays walk them.
  vtkSmartPointer<vtkTextureObject> Cells;
  bool CellWalk = false;
  vtkSmartPointer<vtkTextureObject> Transfer;
  vtkSmartPointer<vtkTextureObject> OpaqueDepth;
  vtkVolumeCutBrickAtlas BrickAtlases[vtkVolumeCutOpenGLRayCaster::MaximumNumberOfCutFields];
  // What the opaque depth texture holds (it travels only when that changes),
  // and a count of its uploads.
  bool UploadedHadOpaqueDepth = false;
  std::vector<float> UploadedOpaqueDepth;
  vtkTypeUInt64 OpaqueDepthVersion = 0;
  vtkMTimeType AnatomyVersion = 0;
  vtkMTimeType LabelVersion = 0;
  vtkMTimeType SceneVersion = 0;
  // How the CT and labels were uploaded: NormalizedTextures then, the CT's
  // format and the values that turn texels back into CT values and labels.
  bool TexturesNormalized = false;
  bool AnatomyUnorm16 = false;
  bool FractionsUnorm16 = false;
  float AnatomyMinimum = 0.f;
  float LabelScale = 1.f;
  int AnatomyBytesPerVoxel = 0;
  int LabelBytesPerVoxel = 0;
  int FractionBytesPerVoxel = 0;
};

#endif
