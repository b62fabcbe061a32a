// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutTextureUtilities
 * @brief   How vtkVolumeCutOpenGLRayCaster makes its textures and asks what the driver made of them.
 *
 * Every texture of the GPU path is clamped at its edges and fetched texel by
 * texel unless filtering is asked for (SetLinearFiltering); a format the
 * driver does not offer can yield a texture with no storage, which
 * BytesPerVoxel tells (0) so that the caller falls back to floats.
 */
#ifndef vtkVolumeCutTextureUtilities_h
#define vtkVolumeCutTextureUtilities_h

#include <vtkSmartPointer.h>

class vtkOpenGLRenderWindow;
class vtkTextureObject;
class vtkWindow;

class vtkVolumeCutTextureUtilities
{
public:
  /// A float 3D texture (R32F .. RGBA32F by components); nullptr if it cannot be made.
  static vtkSmartPointer<vtkTextureObject> Texture3D(
    vtkOpenGLRenderWindow* window, int x, int y, int z, int components, const float* data);

  /**
   * A 3D texture of unsigned normalized integers (GL_R8 from unsigned char,
   * GL_R16 or GL_RGBA16 from unsigned short) or, with internalFormat 0,
   * VTK's choice for the type (R32F/RGBA32F for floats).
   */
  static vtkSmartPointer<vtkTextureObject> Texture3D(vtkOpenGLRenderWindow* window, int x, int y, int z, int components,
    int vtkType, unsigned int internalFormat, const void* data);

  /// A float 2D texture (lookup tables, depths); nullptr if it cannot be made.
  static vtkSmartPointer<vtkTextureObject> Texture2D(vtkOpenGLRenderWindow* window, int x, int y, int components, const float* data);

  /**
   * Texel fetches ignore the filter, so one texture serves both the
   * texture unit's interpolation (linear) and the shader's exact per-texel
   * reads (nearest).
   */
  static void SetLinearFiltering(vtkTextureObject* texture, bool linear);

  /**
   * Bytes per voxel of the first component of a 3D texture as the driver
   * stores it (0 where the driver made none, e.g. a format it does not offer).
   */
  static int BytesPerVoxel(vtkTextureObject* texture);

  /// Bytes of the texture's texels as uploaded (its type's size times its texels and components); 0 for none.
  static size_t MemorySize(vtkTextureObject* texture);

  /// Release the texture's GPU storage, if there is a texture.
  static void Release(vtkTextureObject* texture, vtkWindow* window);
};

#endif
