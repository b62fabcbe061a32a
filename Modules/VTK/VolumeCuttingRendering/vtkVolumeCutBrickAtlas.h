// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutBrickAtlas
 * @brief   One cut field on the GPU for vtkVolumeCutOpenGLRayCaster: a page table and an atlas of its 8^3 bricks.
 *
 * The page table holds a texel per brick of the field: the brick's slot in
 * the atlas, -1 where the field allocated none. The atlas holds the bricks'
 * distances (short quanta) in slots of 8^3 texels. Update() uploads only the
 * bricks modified since the last upload (vtkVolumeCutField's modification
 * stamps); when the atlas is full it is made again with room to grow by
 * half, and every brick travels.
 */
#ifndef vtkVolumeCutBrickAtlas_h
#define vtkVolumeCutBrickAtlas_h

#include <vtkSmartPointer.h>
#include <vtkTextureObject.h> // For the getters
#include <vtkType.h>

#include <vector>

class vtkOpenGLRenderWindow;
class vtkVolumeCutField;
class vtkWindow;

class vtkVolumeCutBrickAtlas
{
public:
  vtkVolumeCutBrickAtlas() = default;
  vtkVolumeCutBrickAtlas(const vtkVolumeCutBrickAtlas&) = delete;
  void operator=(const vtkVolumeCutBrickAtlas&) = delete;

  /**
   * Bring the page table and atlas up to date with \a field in window's
   * context (current). normalized asks for an R16 atlas (distance + 32768,
   * exact; R32F where the driver offers no R16). Returns the number of
   * bricks uploaded, or -1 when a texture cannot be made.
   */
  vtkIdType Update(vtkOpenGLRenderWindow* window, vtkVolumeCutField* field, bool normalized);

  /// Release the textures and forget the field.
  void Release(vtkWindow* window);

  vtkTextureObject* GetPageTable() const { return this->PageTable; }
  vtkTextureObject* GetAtlas() const { return this->Atlas; }
  /// Whether the atlas holds distance + 32768 in R16 (else the distances as R32F).
  bool GetUnorm16() const { return this->Unorm16; }
  /// Bytes of an atlas texel as the driver stores it (2 for R16, 4 for R32F; 0 without an atlas).
  int GetBytesPerTexel() const { return this->AtlasBytesPerTexel; }
  /// Slots along each axis of the atlas (8 texels each).
  int GetSlotsPerAxis() const { return this->SlotsPerAxis; }
  /// The field's sub-voxel grid when uploaded.
  const int* GetDimensions() const { return this->Dimensions; }

private:
  // As new: no field, no textures (the textures are not released here).
  void Clear();

  vtkVolumeCutField* Field = nullptr;
  vtkSmartPointer<vtkTextureObject> PageTable;
  vtkSmartPointer<vtkTextureObject> Atlas;
  int SlotsPerAxis = 0;
  int UsedSlots = 0;
  std::vector<int> SlotOfBrick;
  vtkTypeUInt64 Stamp = 0;
  int Dimensions[3] = { 0, 0, 0 };
  // The atlas as asked (NormalizedTextures) and as made.
  bool Unorm16Requested = false;
  bool Unorm16 = false;
  int AtlasBytesPerTexel = 0;
};

#endif
