// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutKeptImage
 * @brief   vtkVolumeCutOpenGLRayCaster's last image and what it was cast from, for localized recasts after a stroke.
 *
 * The ray caster casts into this framebuffer (float colour and depth of the
 * viewport's size, so it holds exactly what the shader wrote) and the image
 * is then drawn into the window. A frame from the same state as the kept
 * image but for the cut fields' contents (a burr stroke) recasts only the
 * rectangle over the bricks modified since then (vtkVolumeCutLocalizedUpdate),
 * scissored; the rest of the kept image is drawn again as it was.
 */
#ifndef vtkVolumeCutKeptImage_h
#define vtkVolumeCutKeptImage_h

#include <vtkSmartPointer.h>
#include <vtkType.h>

#include <memory>
#include <string>
#include <vector>

class vtkOpenGLFramebufferObject;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkOpenGLVertexArrayObject;
class vtkTextureObject;
class vtkVolumeCutField;
class vtkWindow;

class vtkVolumeCutKeptImage
{
public:
  /// What an image was cast from: a change of any of these but the stamps asks for a full cast.
  struct Source
  {
    double WorldToNDC[16] = {};
    vtkMTimeType SceneVersion = 0;
    vtkMTimeType AnatomyVersion = 0;
    vtkMTimeType LabelVersion = 0;
    std::string ProgramKey;
    bool EmptySpaceSkipping = true;
    // vtkVolumeCutSceneTextures::GetOpaqueDepthVersion() when it was cast.
    vtkTypeUInt64 OpaqueDepthVersion = 0;
    std::vector<vtkVolumeCutField*> Fields;
    /// The fields' counters before their bricks were uploaded: a brick stamped after them is recast next time.
    std::vector<vtkTypeUInt64> Stamps;
  };

  vtkVolumeCutKeptImage();
  ~vtkVolumeCutKeptImage();
  vtkVolumeCutKeptImage(const vtkVolumeCutKeptImage&) = delete;
  void operator=(const vtkVolumeCutKeptImage&) = delete;

  /// Whether the kept image is width x height and was cast from \a source but for the cut fields' contents.
  bool CastFrom(const Source& source, int width, int height) const;

  /**
   * The rectangle (x0, y0, x1, y1, inclusive; empty when x1 < x0) of a
   * width x height image seen through \a worldToNDC (row-major) whose rays
   * may meet a brick modified since the kept image was cast, or whose
   * shading looks up to \a reach (mm) into one.
   */
  void GetModifiedRegion(const double worldToNDC[16], int width, int height, double reach, int region[4]) const;

  /// Make the framebuffer width x height if it is not (the image is lost); false if the context cannot.
  bool Reserve(vtkOpenGLRenderWindow* window, int width, int height);

  /// Until Keep(): the image is being cast and matches nothing.
  void Invalidate() { this->Valid = false; }

  /**
   * Cast the rays of \a region (x0, y0, x1, y1 of the viewport) into the
   * image with the ray caster's program bound, drawing \a quad; the rest of
   * it stays as it was.
   */
  void Cast(vtkOpenGLRenderWindow* window, const int region[4], vtkOpenGLVertexArrayObject* quad);

  /// The image is now the one cast from \a source.
  void Keep(const Source& source);

  /// Draw the image into the window's viewport as the ray caster would; false if its shader does not compile.
  bool Draw(vtkOpenGLRenderWindow* window);

  void Release(vtkWindow* window);

  /// GPU memory (bytes) of the colour and depth textures.
  size_t GetMemorySize() const;

private:
  // A float colour and depth framebuffer of width x height.
  bool Allocate(vtkOpenGLRenderWindow* window, int width, int height);

  vtkSmartPointer<vtkOpenGLFramebufferObject> Framebuffer;
  vtkSmartPointer<vtkTextureObject> Color;
  vtkSmartPointer<vtkTextureObject> Depth;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  bool Valid = false;
  int Width = 0;
  int Height = 0;
  Source CastSource;
};

#endif
