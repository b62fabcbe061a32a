// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutVolumeMapper
 * @brief   Volume mapper that renders anatomy and cut fields with adaptive multivolume sampling.
 *
 * A vtkVolumeMapper for a vtkVolume in any VTK renderer (Slicer's 3D views
 * included): its input is the anatomy's CT; GetRayCaster() holds the rest of
 * the scene (label map and segment appearances, cut fields, iso-value,
 * thin-bone shading) and is the CPU reference. Each frame it runs the GLSL
 * implementation (vtkVolumeCutOpenGLRayCaster) when the OpenGL context can
 * run it on graphics hardware, and otherwise casts the rays on the CPU and
 * draws the image; both
 * write the depth of the first visible surface, so other actors (the tool
 * glyph, models, markups) composite correctly, and both stop rays at opaque
 * geometry already drawn. GetLastRenderPath() says which ran, and a change of
 * path is reported once in the log with the reason.
 *
 * The volume's matrix and the image's geometry place the CT in world
 * coordinates (in Slicer: IJK-to-RAS); cut fields are in world coordinates.
 * Blend modes: ISOSURFACE_BLEND (default, surfaces per segment) and
 * COMPOSITE_BLEND (the volume property's transfer functions, with the cuts).
 * The mapper's clipping planes become clip surfaces. Stereo works as for any
 * mapper: the renderer draws each eye with its own camera.
 *
 * @sa vtkVolumeCutRayCaster vtkVolumeCutOpenGLRayCaster vtkVolumeCutField
 */

#ifndef vtkVolumeCutVolumeMapper_h
#define vtkVolumeCutVolumeMapper_h

#include "vtkVolumeMapper.h"
#include "vtkVolumeCuttingRenderingExport.h" // For export macro

#include <memory> // For std::unique_ptr

class vtkVolumeCutOpenGLRayCaster;
class vtkVolumeCutRayCaster;

class VTK_VOLUMECUTTINGRENDERING_EXPORT vtkVolumeCutVolumeMapper : public vtkVolumeMapper
{
public:
  static vtkVolumeCutVolumeMapper* New();
  vtkTypeMacro(vtkVolumeCutVolumeMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum RenderPaths
  {
    /// The GPU where the context runs the shader on graphics hardware; the
    /// CPU otherwise (a software rasterizer such as Mesa's llvmpipe runs the
    /// shader, but slower than the multithreaded CPU reference).
    AutomaticPath = 0,
    GPUPath = 1,
    CPUPath = 2
  };

  ///@{
  /** Which implementation to use (AutomaticPath by default). */
  vtkSetClampMacro(RequestedRenderPath, int, AutomaticPath, CPUPath);
  vtkGetMacro(RequestedRenderPath, int);
  ///@}

  /// The implementation that drew the last frame: GPUPath, CPUPath, or 0 if none.
  vtkGetMacro(LastRenderPath, int);
  const char* GetLastRenderPathAsString() const;

  /// Why the GPU path was not used in the last frame (empty if it was).
  const char* GetGPUFallbackReason() const;

  /// The scene besides the CT, and the CPU reference implementation.
  vtkVolumeCutRayCaster* GetRayCaster();

  /// The GPU implementation (statistics: bricks uploaded, texture memory).
  vtkVolumeCutOpenGLRayCaster* GetOpenGLRayCaster();

  /// Seconds the last frame took in this mapper (ray casting and drawing).
  vtkGetMacro(LastFrameTime, double);

  void Render(vtkRenderer* renderer, vtkVolume* volume) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkVolumeCutVolumeMapper();
  ~vtkVolumeCutVolumeMapper() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;

  bool DrawCPUImage(vtkRenderer* renderer, int x0, int y0, int width, int height);

  int RequestedRenderPath = AutomaticPath;
  int LastRenderPath = 0;
  double LastFrameTime = 0.0;

private:
  vtkVolumeCutVolumeMapper(const vtkVolumeCutVolumeMapper&) = delete;
  void operator=(const vtkVolumeCutVolumeMapper&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
