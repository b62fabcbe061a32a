// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutSceneTextures.h"

#include "vtkVolumeCutTextureUtilities.h"

#include <vtkOpenGLRenderWindow.h>
#include <vtkShaderProgram.h>
#include <vtkTextureObject.h>
#include <vtk_glad.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace
{
using Textures = vtkVolumeCutTextureUtilities;

// Whether the CT loses nothing as a 16-bit unsigned normalized texture: each
// value v is minimum + k (float arithmetic, as the shader adds them) for an
// integer k in 0..65535. If so, texels holds each k and minimum is set.
bool ToUnorm16(const float* values, size_t count, float& minimum, std::vector<unsigned short>& texels)
{
  if (count == 0)
  {
    return false;
  }
  // NaNs are skipped here and refused below.
  float low = std::numeric_limits<float>::infinity();
  float high = -std::numeric_limits<float>::infinity();
  for (size_t n = 0; n < count; ++n)
  {
    low = std::min(low, values[n]);
    high = std::max(high, values[n]);
  }
  if (!(static_cast<double>(high) - static_cast<double>(low) <= 65535.0))
  {
    return false;
  }
  texels.resize(count);
  for (size_t n = 0; n < count; ++n)
  {
    const double offset = static_cast<double>(values[n]) - static_cast<double>(low);
    if (!(offset >= 0.0 && offset <= 65535.0))
    {
      return false;
    }
    const int k = static_cast<int>(offset + 0.5);
    if (low + static_cast<float>(k) != values[n])
    {
      return false;
    }
    texels[n] = static_cast<unsigned short>(k);
  }
  minimum = low;
  return true;
}
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneTextures::UpdateScene(
  vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view, bool normalized)
{
  this->ErrorMessage.clear();
  const bool anatomyChanged = !this->Anatomy || this->AnatomyVersion != view.AnatomyVersion || this->TexturesNormalized != normalized;
  if (anatomyChanged && !this->UpdateAnatomy(window, view, normalized))
  {
    return false;
  }
  if (anatomyChanged || !this->Labels || !this->Fractions || this->LabelVersion != view.LabelVersion)
  {
    if (!this->UpdateLabels(window, view, normalized))
    {
      return false;
    }
    this->SceneVersion = 0; // the tables follow
  }
  if (this->SceneVersion != view.Version)
  {
    if (!this->UpdateTables(window, view))
    {
      return false;
    }
    this->SceneVersion = view.Version;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneTextures::UpdateAnatomy(
  vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view, bool normalized)
{
  const int* dims = view.Dimensions;
  const size_t voxels = static_cast<size_t>(dims[0]) * dims[1] * dims[2];
  this->Anatomy = nullptr;
  this->AnatomyUnorm16 = false;
  this->TexturesNormalized = normalized;
  std::vector<unsigned short> texels;
  float minimum = 0.f;
  if (normalized && ToUnorm16(view.Values, voxels, minimum, texels))
  {
    this->Anatomy = Textures::Texture3D(window, dims[0], dims[1], dims[2], 1, VTK_UNSIGNED_SHORT, GL_R16, texels.data());
    if (this->Anatomy && Textures::BytesPerVoxel(this->Anatomy) == 0)
    {
      // A driver without R16 textures: the floats, as before.
      this->Anatomy->ReleaseGraphicsResources(window);
      this->Anatomy = nullptr;
    }
    this->AnatomyUnorm16 = this->Anatomy != nullptr;
    this->AnatomyMinimum = minimum;
  }
  if (!this->Anatomy)
  {
    this->Anatomy = Textures::Texture3D(window, dims[0], dims[1], dims[2], 1, view.Values);
  }
  this->AnatomyBytesPerVoxel = this->Anatomy ? Textures::BytesPerVoxel(this->Anatomy) : 0;
  if (this->AnatomyBytesPerVoxel == 0)
  {
    // No texture, or the driver could not allocate it (GL_OUT_OF_MEMORY).
    if (this->Anatomy)
    {
      this->Anatomy->ReleaseGraphicsResources(window);
      this->Anatomy = nullptr;
    }
    this->ErrorMessage = "the CT does not fit in GPU memory as a float 3D texture";
    return false;
  }
  this->AnatomyVersion = view.AnatomyVersion;
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneTextures::UpdateLabels(
  vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view, bool normalized)
{
  const int* dims = view.Dimensions;
  const size_t voxels = static_cast<size_t>(dims[0]) * dims[1] * dims[2];
  this->Labels = nullptr;
  if (view.Labels && normalized)
  {
    // Labels are 0..65535: R16 is always exact, R8 when they fit in a byte.
    const unsigned short largest = *std::max_element(view.Labels, view.Labels + voxels);
    if (largest <= 255)
    {
      const std::vector<unsigned char> bytes(view.Labels, view.Labels + voxels);
      this->Labels = Textures::Texture3D(window, dims[0], dims[1], dims[2], 1, VTK_UNSIGNED_CHAR, GL_R8, bytes.data());
      this->LabelScale = 255.f;
    }
    else
    {
      this->Labels = Textures::Texture3D(window, dims[0], dims[1], dims[2], 1, VTK_UNSIGNED_SHORT, GL_R16, view.Labels);
      this->LabelScale = 65535.f;
    }
    if (this->Labels && Textures::BytesPerVoxel(this->Labels) == 0)
    {
      this->Labels->ReleaseGraphicsResources(window);
      this->Labels = nullptr;
    }
  }
  if (!this->Labels)
  {
    std::vector<float> labels(view.Labels ? voxels : 8, 0.f);
    if (view.Labels)
    {
      std::copy(view.Labels, view.Labels + voxels, labels.begin());
    }
    this->Labels = view.Labels ? Textures::Texture3D(window, dims[0], dims[1], dims[2], 1, labels.data())
                               : Textures::Texture3D(window, 2, 2, 2, 1, labels.data());
    this->LabelScale = 1.f;
  }
  this->LabelBytesPerVoxel = this->Labels && view.Labels ? Textures::BytesPerVoxel(this->Labels) : 0;
  // Up to four segments' fractions, one per channel: RGBA16, as the CPU
  // holds them in 0..1 (each within 1/131070 of its value, far inside the
  // CPU/GPU tolerance of the mapper tests), else RGBA32F.
  this->Fractions = nullptr;
  this->FractionsUnorm16 = false;
  if (!view.Fractions.empty() && normalized)
  {
    std::vector<unsigned short> quantized(4 * voxels, 0);
    for (size_t i = 0; i < view.Fractions.size(); ++i)
    {
      const float* fraction = view.Fractions[i].second;
      for (size_t n = 0; n < voxels; ++n)
      {
        quantized[4 * n + i] = static_cast<unsigned short>(std::min(std::max(fraction[n], 0.f), 1.f) * 65535.f + 0.5f);
      }
    }
    this->Fractions = Textures::Texture3D(window, dims[0], dims[1], dims[2], 4, VTK_UNSIGNED_SHORT, GL_RGBA16, quantized.data());
    if (this->Fractions && Textures::BytesPerVoxel(this->Fractions) == 0)
    {
      this->Fractions->ReleaseGraphicsResources(window);
      this->Fractions = nullptr;
    }
    this->FractionsUnorm16 = this->Fractions != nullptr;
  }
  if (!this->Fractions)
  {
    std::vector<float> fractions(view.Fractions.empty() ? 32 : 4 * voxels, 0.f);
    for (size_t i = 0; i < view.Fractions.size(); ++i)
    {
      for (size_t n = 0; n < voxels; ++n)
      {
        fractions[4 * n + i] = view.Fractions[i].second[n];
      }
    }
    this->Fractions = view.Fractions.empty() ? Textures::Texture3D(window, 2, 2, 2, 4, fractions.data())
                                             : Textures::Texture3D(window, dims[0], dims[1], dims[2], 4, fractions.data());
  }
  this->FractionBytesPerVoxel = this->Fractions && !view.Fractions.empty() ? 4 * Textures::BytesPerVoxel(this->Fractions) : 0;
  if (!this->Labels || !this->Fractions)
  {
    this->ErrorMessage = "the label map or fractional labelmaps do not fit in GPU memory";
    this->Labels = this->Fractions = nullptr;
    return false;
  }
  this->LabelVersion = view.LabelVersion;
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneTextures::UpdateTables(vtkOpenGLRenderWindow* window, const vtkVolumeCutRayCaster::SceneView& view)
{
  std::vector<float> styles(12 * view.Styles.size());
  const int styleCount = static_cast<int>(view.Styles.size());
  for (int label = 0; label < styleCount; ++label)
  {
    std::copy(view.Styles[label].begin(), view.Styles[label].begin() + 4, styles.begin() + 4 * label);
    std::copy(view.Styles[label].begin() + 4, view.Styles[label].begin() + 8, styles.begin() + 4 * (styleCount + label));
    std::copy(view.Styles[label].begin() + 8, view.Styles[label].end(), styles.begin() + 4 * (2 * styleCount + label));
  }
  this->Styles = Textures::Texture2D(window, styleCount, 3, 4, styles.data());
  const int* bd = view.BlockDimensions;
  const size_t blocks = static_cast<size_t>(bd[0]) * bd[1] * bd[2];
  std::vector<float> blockData(2 * blocks);
  for (size_t n = 0; n < blocks; ++n)
  {
    // The reach (0 for an occupied block) says both whether a block is
    // empty and how far around it the ray may jump.
    blockData[2 * n] = view.BlockOccupied[n] ? 0.f : float(std::max<int>(view.BlockReach[n], 1));
    blockData[2 * n + 1] = std::isfinite(view.BlockLipschitz[n]) ? view.BlockLipschitz[n] : 1e30f;
  }
  this->Blocks = Textures::Texture3D(window, bd[0], bd[1], bd[2], 2, blockData.data());
  // The cells' bytes as the CPU holds them; one byte with every cell kept
  // where cells are not classified (the walk is off then).
  const int* gd = view.CellGroupDimensions;
  const unsigned char everyCell = 0xff;
  this->Cells = view.CellGroups ? Textures::Texture3D(window, gd[0], gd[1], gd[2], 1, VTK_UNSIGNED_CHAR, GL_R8, view.CellGroups)
                                : Textures::Texture3D(window, 1, 1, 1, 1, VTK_UNSIGNED_CHAR, GL_R8, &everyCell);
  this->CellWalk = view.CellGroups != nullptr;
  if (this->Cells && Textures::BytesPerVoxel(this->Cells) != 1)
  {
    // A driver without exact R8 texels: no walk rather than a wrong one.
    this->Cells->ReleaseGraphicsResources(window);
    this->Cells = Textures::Texture3D(window, 1, 1, 1, 1, VTK_UNSIGNED_CHAR, GL_R8, &everyCell);
    this->CellWalk = false;
  }
  std::vector<float> transfer(4 * std::max(view.TableSize, 2), 0.f);
  if (view.ColorTable && view.OpacityTable)
  {
    for (int n = 0; n < view.TableSize; ++n)
    {
      std::copy(view.ColorTable + 3 * n, view.ColorTable + 3 * n + 3, transfer.begin() + 4 * n);
      transfer[4 * n + 3] = view.OpacityTable[n];
    }
  }
  this->Transfer = Textures::Texture2D(window, std::max(view.TableSize, 2), 1, 4, transfer.data());
  if (!this->Styles || !this->Blocks || !this->Cells || !this->Transfer)
  {
    this->ErrorMessage = "the lookup tables do not fit in GPU memory";
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneTextures::UpdateCutFields(
  vtkOpenGLRenderWindow* window, const std::vector<vtkVolumeCutField*>& fields, bool normalized, vtkIdType& uploaded)
{
  this->ErrorMessage.clear();
  uploaded = 0;
  for (size_t n = 0; n < fields.size(); ++n)
  {
    const vtkIdType bricks = this->BrickAtlases[n].Update(window, fields[n], normalized);
    if (bricks < 0)
    {
      this->ErrorMessage = "cut field " + std::to_string(n) + " does not fit in GPU memory";
      return false;
    }
    uploaded += bricks;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutSceneTextures::UpdateOpaqueDepth(vtkOpenGLRenderWindow* window, const float* opaqueDepth, int width, int height)
{
  this->ErrorMessage.clear();
  const size_t pixels = static_cast<size_t>(width) * height;
  const bool sameDepth = this->UploadedHadOpaqueDepth == (opaqueDepth != nullptr) &&
    (!opaqueDepth ||
      (this->UploadedOpaqueDepth.size() == pixels &&
        std::memcmp(opaqueDepth, this->UploadedOpaqueDepth.data(), pixels * sizeof(float)) == 0));
  if (this->OpaqueDepth && sameDepth)
  {
    return true;
  }
  std::vector<float> depth(pixels, 1.f);
  if (opaqueDepth)
  {
    std::copy(opaqueDepth, opaqueDepth + pixels, depth.begin());
  }
  this->OpaqueDepth = Textures::Texture2D(window, width, height, 1, depth.data());
  if (!this->OpaqueDepth)
  {
    this->ErrorMessage = "no memory for the depth texture";
    return false;
  }
  this->UploadedHadOpaqueDepth = opaqueDepth != nullptr;
  this->UploadedOpaqueDepth.clear();
  if (opaqueDepth)
  {
    this->UploadedOpaqueDepth.assign(opaqueDepth, opaqueDepth + pixels);
  }
  ++this->OpaqueDepthVersion;
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutSceneTextures::SetFiltering(bool anatomyLinear, bool fractionsLinear)
{
  Textures::SetLinearFiltering(this->Anatomy, anatomyLinear);
  Textures::SetLinearFiltering(this->Fractions, fractionsLinear);
}

//------------------------------------------------------------------------------
void vtkVolumeCutSceneTextures::Activate(vtkShaderProgram* program, int cutFields, std::vector<vtkTextureObject*>& active)
{
  auto bind = [&](vtkTextureObject* texture, const char* name) {
    texture->Activate();
    program->SetUniformi(name, texture->GetTextureUnit());
    active.push_back(texture);
  };
  bind(this->Anatomy, "anatomyTexture");
  bind(this->Labels, "labelTexture");
  bind(this->Fractions, "fractionTexture");
  bind(this->Styles, "styleTexture");
  bind(this->Blocks, "blockTexture");
  bind(this->Cells, "cellTexture");
  bind(this->OpaqueDepth, "opaqueDepthTexture");
  bind(this->Transfer, "transferTexture");
  for (int n = 0; n < cutFields; ++n)
  {
    const std::string index = std::to_string(n);
    bind(this->BrickAtlases[n].GetPageTable(), ("cutPage" + index).c_str());
    bind(this->BrickAtlases[n].GetAtlas(), ("cutAtlas" + index).c_str());
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutSceneTextures::Release(vtkWindow* window)
{
  for (vtkTextureObject* texture : { this->Anatomy.GetPointer(), this->Labels.GetPointer(), this->Fractions.GetPointer(),
         this->Styles.GetPointer(), this->Blocks.GetPointer(), this->Cells.GetPointer(), this->Transfer.GetPointer(),
         this->OpaqueDepth.GetPointer() })
  {
    Textures::Release(texture, window);
  }
  this->Anatomy = this->Labels = this->Fractions = this->Styles = this->Blocks = this->Cells = this->Transfer = this->OpaqueDepth =
    nullptr;
  for (vtkVolumeCutBrickAtlas& atlas : this->BrickAtlases)
  {
    atlas.Release(window);
  }
  this->UploadedOpaqueDepth.clear();
  this->AnatomyVersion = 0;
  this->LabelVersion = 0;
  this->SceneVersion = 0;
  this->AnatomyUnorm16 = false;
  this->FractionsUnorm16 = false;
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutSceneTextures::GetMemorySize() const
{
  size_t bytes = 0;
  for (vtkTextureObject* texture : { this->Anatomy.GetPointer(), this->Labels.GetPointer(), this->Fractions.GetPointer(),
         this->Styles.GetPointer(), this->Blocks.GetPointer(), this->Cells.GetPointer(), this->Transfer.GetPointer(),
         this->OpaqueDepth.GetPointer() })
  {
    bytes += Textures::MemorySize(texture);
  }
  for (const vtkVolumeCutBrickAtlas& atlas : this->BrickAtlases)
  {
    bytes += Textures::MemorySize(atlas.GetPageTable());
    bytes += Textures::MemorySize(atlas.GetAtlas());
  }
  return bytes;
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutSceneTextures::GetCutAtlasTexels() const
{
  vtkIdType texels = 0;
  for (const vtkVolumeCutBrickAtlas& atlas : this->BrickAtlases)
  {
    if (vtkTextureObject* texture = atlas.GetAtlas())
    {
      texels += static_cast<vtkIdType>(texture->GetWidth()) * texture->GetHeight() * texture->GetDepth();
    }
  }
  return texels;
}
