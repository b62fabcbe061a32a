// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutBrickAtlas.h"

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutTextureUtilities.h"

#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkTextureObject.h>
#include <vtk_glad.h>

#include <algorithm>
#include <cmath>

namespace
{
// A cut field's distances (short quanta) travel in R16 as value + this; the
// shader subtracts it (glsl/vtkVolumeCutCutFieldFS.glsl).
constexpr int CutAtlasOffset = 32768;
}

//------------------------------------------------------------------------------
void vtkVolumeCutBrickAtlas::Clear()
{
  this->Field = nullptr;
  this->PageTable = nullptr;
  this->Atlas = nullptr;
  this->SlotsPerAxis = 0;
  this->UsedSlots = 0;
  this->SlotOfBrick.clear();
  this->Stamp = 0;
  std::fill(this->Dimensions, this->Dimensions + 3, 0);
  this->Unorm16Requested = false;
  this->Unorm16 = false;
  this->AtlasBytesPerTexel = 0;
}

//------------------------------------------------------------------------------
void vtkVolumeCutBrickAtlas::Release(vtkWindow* window)
{
  if (this->PageTable)
  {
    this->PageTable->ReleaseGraphicsResources(window);
    this->Atlas->ReleaseGraphicsResources(window);
  }
  this->Clear();
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutBrickAtlas::Update(vtkOpenGLRenderWindow* window, vtkVolumeCutField* field, bool normalized)
{
  using Textures = vtkVolumeCutTextureUtilities;
  const int* brickDims = field->GetBrickDimensions();
  const vtkIdType brickCount = static_cast<vtkIdType>(brickDims[0]) * brickDims[1] * brickDims[2];
  const int* dims = field->GetDimensions();
  const bool sameField = this->Field == field && this->PageTable && this->Dimensions[0] == dims[0] &&
    this->Dimensions[1] == dims[1] && this->Dimensions[2] == dims[2] && this->Unorm16Requested == normalized;
  // The counter first: a brick stamped after it is listed next time.
  const vtkTypeUInt64 stamp = field->GetCurrentStamp();
  vtkNew<vtkIdList> modified;
  field->GetBricksModifiedSince(sameField ? this->Stamp : 0, modified);
  if (sameField && modified->GetNumberOfIds() == 0)
  {
    this->Stamp = stamp;
    return 0;
  }
  // Slots needed: those in use plus the new bricks.
  int newBricks = 0;
  if (sameField)
  {
    for (vtkIdType n = 0; n < modified->GetNumberOfIds(); ++n)
    {
      newBricks += this->SlotOfBrick[modified->GetId(n)] < 0 ? 1 : 0;
    }
  }
  const bool rebuild = !sameField || this->UsedSlots + newBricks > this->SlotsPerAxis * this->SlotsPerAxis * this->SlotsPerAxis;
  if (rebuild)
  {
    if (sameField)
    {
      // The atlas is full: start again with room to grow, uploading every brick.
      field->GetBricksModifiedSince(0, modified);
    }
    const vtkIdType needed = std::max<vtkIdType>(8, field->GetNumberOfAllocatedBricks() + modified->GetNumberOfIds());
    int slots = static_cast<int>(std::ceil(std::cbrt(1.5 * static_cast<double>(needed))));
    GLint maximum3D = 0;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &maximum3D);
    if (8 * slots > maximum3D || brickDims[0] > maximum3D || brickDims[1] > maximum3D || brickDims[2] > maximum3D)
    {
      return -1;
    }
    std::vector<float> page(brickCount, -1.f);
    this->Clear();
    this->PageTable = Textures::Texture3D(window, brickDims[0], brickDims[1], brickDims[2], 1, page.data());
    const size_t atlasTexels = static_cast<size_t>(8 * slots) * 8 * slots * 8 * slots;
    if (normalized)
    {
      // Distances are whole quanta, -32767..32767 (32767: no brick there):
      // shifted by 32768 they fit R16 exactly, half the floats' memory and upload.
      std::vector<unsigned short> empty(atlasTexels, static_cast<unsigned short>(32767 + CutAtlasOffset));
      this->Atlas = Textures::Texture3D(window, 8 * slots, 8 * slots, 8 * slots, 1, VTK_UNSIGNED_SHORT, GL_R16, empty.data());
      if (this->Atlas && Textures::BytesPerVoxel(this->Atlas) == 0)
      {
        this->Atlas->ReleaseGraphicsResources(window);
        this->Atlas = nullptr;
      }
      this->Unorm16 = this->Atlas != nullptr;
    }
    if (!this->Atlas)
    {
      std::vector<float> empty(atlasTexels, 32767.f);
      this->Atlas = Textures::Texture3D(window, 8 * slots, 8 * slots, 8 * slots, 1, empty.data());
    }
    if (!this->PageTable || !this->Atlas)
    {
      this->Clear();
      return -1;
    }
    this->Unorm16Requested = normalized;
    this->AtlasBytesPerTexel = Textures::BytesPerVoxel(this->Atlas);
    this->Field = field;
    this->SlotsPerAxis = slots;
    this->SlotOfBrick.assign(brickCount, -1);
    std::copy(dims, dims + 3, this->Dimensions);
  }
  std::vector<short> values(vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize);
  std::vector<float> floats(this->Unorm16 ? 0 : values.size());
  std::vector<unsigned short> shifted(this->Unorm16 ? values.size() : 0);
  vtkIdType uploaded = 0;
  for (vtkIdType n = 0; n < modified->GetNumberOfIds(); ++n)
  {
    const vtkIdType id = modified->GetId(n);
    field->CopyBrick(id, values.data());
    if (this->Unorm16)
    {
      std::transform(values.begin(), values.end(), shifted.begin(),
        [](short value) { return static_cast<unsigned short>(value + CutAtlasOffset); });
    }
    else
    {
      std::copy(values.begin(), values.end(), floats.begin());
    }
    int& slot = this->SlotOfBrick[id];
    if (slot < 0)
    {
      slot = this->UsedSlots++;
      const float slotValue = static_cast<float>(slot);
      const int b[3] = { static_cast<int>(id % brickDims[0]), static_cast<int>((id / brickDims[0]) % brickDims[1]),
        static_cast<int>(id / (static_cast<vtkIdType>(brickDims[0]) * brickDims[1])) };
      this->PageTable->Bind();
      glTexSubImage3D(GL_TEXTURE_3D, 0, b[0], b[1], b[2], 1, 1, 1, GL_RED, GL_FLOAT, &slotValue);
    }
    const int s = this->SlotsPerAxis;
    this->Atlas->Bind();
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    if (this->Unorm16)
    {
      glTexSubImage3D(GL_TEXTURE_3D, 0, 8 * (slot % s), 8 * ((slot / s) % s), 8 * (slot / (s * s)), 8, 8, 8, GL_RED,
        GL_UNSIGNED_SHORT, shifted.data());
    }
    else
    {
      glTexSubImage3D(GL_TEXTURE_3D, 0, 8 * (slot % s), 8 * ((slot / s) % s), 8 * (slot / (s * s)), 8, 8, 8, GL_RED, GL_FLOAT,
        floats.data());
    }
    ++uploaded;
  }
  this->Stamp = stamp;
  return uploaded;
}
