// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutOpenGLRayCaster
 * @brief   GPU (OpenGL/GLSL) implementation of vtkVolumeCutRayCaster's algorithm.
 *
 * Draws one full-viewport quad whose fragment shader casts the pixel's ray
 * through the scene prepared by a vtkVolumeCutRayCaster: the CT and labels as
 * 3D textures fetched texel by texel (the same trilinear arithmetic as the
 * CPU), each cut field as a page table (one texel a brick) and an atlas of
 * 8^3 bricks in which only bricks modified since the last frame are
 * re-uploaded (vtkVolumeCutField's modification stamps). It writes colour
 * (premultiplied) and the depth of the first visible surface.
 *
 * Render() returns false with GetLastErrorMessage() set, and draws nothing,
 * when the context cannot run it (shader does not compile, volume larger than
 * the 3D texture limit, too many cut fields, texture allocation failed); the
 * caller then uses the CPU reference.
 *
 * @sa vtkVolumeCutVolumeMapper vtkVolumeCutRayCaster
 */

#ifndef vtkVolumeCutOpenGLRayCaster_h
#define vtkVolumeCutOpenGLRayCaster_h

#include "vtkObject.h"
#include "vtkVolumeCuttingRenderingExport.h" // For export macro

#include <memory>  // For std::unique_ptr
#include <string>  // For the error message

class vtkMatrix4x4;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkVolumeCutRayCaster;
class vtkWindow;

class VTK_VOLUMECUTTINGRENDERING_EXPORT vtkVolumeCutOpenGLRayCaster : public vtkObject
{
public:
  static vtkVolumeCutOpenGLRayCaster* New();
  vtkTypeMacro(vtkVolumeCutOpenGLRayCaster, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Cut fields the shader handles together (more fall back to the CPU).
  static constexpr int MaximumNumberOfCutFields = 4;

  /**
   * Cast the rays of the viewport (origin x0, y0; width x height pixels) of
   * the current framebuffer of \a window through the scene of \a scene seen
   * with \a worldToNDC. \a opaqueDepth (width x height window depths, or
   * nullptr) stops rays at opaque geometry drawn before.
   */
  bool Render(vtkOpenGLRenderWindow* window, vtkVolumeCutRayCaster* scene, vtkMatrix4x4* worldToNDC, int x0, int y0, int width,
    int height, const float* opaqueDepth);

  /// Why the last Render returned false (empty after a success).
  const char* GetLastErrorMessage() const { return this->LastErrorMessage.c_str(); }

  /// Bricks of cut fields uploaded by the last Render, and in total.
  vtkGetMacro(NumberOfBricksUploaded, vtkIdType);
  vtkGetMacro(TotalNumberOfBricksUploaded, vtkIdType);

  /// GPU memory (bytes) held by this object's textures.
  size_t GetTextureMemorySize() const;

  void ReleaseGraphicsResources(vtkWindow* window);

  /**
   * Draw a full-viewport quad whose fragments carry premultiplied colour and
   * gl_FragDepth: blended over the framebuffer, writing depth (the state is
   * restored after). Both paths draw their images this way.
   */
  static void DrawSurfaceQuad(vtkOpenGLRenderWindow* window, vtkOpenGLQuadHelper* quad);

protected:
  vtkVolumeCutOpenGLRayCaster();
  ~vtkVolumeCutOpenGLRayCaster() override;

  std::string LastErrorMessage;
  vtkIdType NumberOfBricksUploaded = 0;
  vtkIdType TotalNumberOfBricksUploaded = 0;

private:
  vtkVolumeCutOpenGLRayCaster(const vtkVolumeCutOpenGLRayCaster&) = delete;
  void operator=(const vtkVolumeCutOpenGLRayCaster&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
