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
 * The GPU path never blocks the view for longer than ProgramBuildTimeLimit
 * (issue 12): the program is built for the features in use; where the
 * driver compiles in parallel, the CPU image is drawn until the program is
 * ready (the interactor, if any, is asked for a frame every 100 ms until
 * then); a build that takes longer than the limit, or a driver that rejects
 * the program, a volume beyond the 3D texture limit or a lost context
 * leaves the CPU path drawing, with the reason (driver, measured time) in
 * GetGPUFallbackReason() and once in the log. Program binaries are cached on
 * disk (ProgramCacheDirectory), so a second start builds nothing.
 * A GPU path requested explicitly that cannot run draws the CPU image too.
 *
 * The volume's matrix and the image's geometry place the CT in world
 * coordinates (in Slicer: IJK-to-RAS); cut fields are in world coordinates.
 * Blend modes: ISOSURFACE_BLEND (default, surfaces per segment) and
 * COMPOSITE_BLEND (the volume property's transfer functions, with the cuts).
 * The mapper's clipping planes become clip surfaces. Stereo works as for any
 * mapper: the renderer draws each eye with its own camera.
 *
 * Progressive refinement on the CPU path, by VTK's convention for
 * interactive volume rendering (vtkSmartVolumeMapper, Slicer's volume
 * rendering): a render is interactive while the render window's
 * DesiredUpdateRate is at or above InteractiveUpdateRate (interactor
 * styles and Slicer's camera widget raise it while the camera moves; the
 * displayable manager raises it while a stroke is drawn). An interactive
 * CPU frame casts one ray per ImageSampleDistance x ImageSampleDistance
 * pixels, the distance chosen from the last reduced frame's measured cost
 * (its fixed work and its cost per ray) so that the window's whole frame
 * fits in 1 / DesiredUpdateRate with a tenth to spare (the rest of the
 * frame, measured between the window's StartEvent and EndEvent, is taken
 * off first; the full image where the last full frame fits, the coarsest
 * before any reduced frame), without ambient occlusion; the image is
 * magnified. The first
 * still render (the rate lowered again when the motion stops) casts every
 * pixel and is the same image as a render that never interacted.
 *
 * @sa vtkVolumeCutRayCaster vtkVolumeCutOpenGLRayCaster vtkVolumeCutField
 */

#ifndef vtkVolumeCutVolumeMapper_h
#define vtkVolumeCutVolumeMapper_h

#include "vtkVolumeMapper.h"
#include "vtkVolumeCuttingRenderingExport.h" // For export macro

#include <memory> // For std::unique_ptr
#include <vector> // For std::vector

class vtkMatrix4x4;
class vtkRenderer;

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

  ///@{
  /**
   * Set/get the longest, in seconds, that building the GPU program may keep
   * the GPU path from drawing; past it the CPU path draws for the rest of the
   * session (setting the limit again lets the GPU try once more). Default is
   * 10. Forwarded to vtkVolumeCutOpenGLRayCaster.
   */
  void SetProgramBuildTimeLimit(double seconds);
  double GetProgramBuildTimeLimit();
  ///@}

  ///@{
  /**
   * Set/get the folder of cached GPU program binaries; empty (the default)
   * for $XDG_CACHE_HOME/VolumeCutting/programs (~/.cache/... without it).
   * Forwarded to vtkVolumeCutOpenGLRayCaster.
   */
  void SetProgramCacheDirectory(const char* directory);
  const char* GetProgramCacheDirectory();
  ///@}

  /// Seconds the last GPU program build took (compile and link, or loading it from the cache).
  double GetLastProgramBuildTime();

  /// The scene besides the CT, and the CPU reference implementation.
  vtkVolumeCutRayCaster* GetRayCaster();

  /// The GPU implementation (statistics: bricks uploaded, texture memory).
  vtkVolumeCutOpenGLRayCaster* GetOpenGLRayCaster();

  /// Seconds the last frame took in this mapper (ray casting and drawing).
  vtkGetMacro(LastFrameTime, double);

  /**
   * Seconds the render window's last frame took besides this mapper (0
   * before one was timed): what an interactive CPU frame leaves the rest of
   * the window.
   */
  double GetRestOfFrameTime() const;

  ///@{
  /**
   * Set/get the render window's DesiredUpdateRate (frames per second) at or
   * above which a render is interactive and the CPU path may cast fewer
   * rays than pixels (as vtkSmartVolumeMapper). Default is 1.0.
   */
  vtkSetClampMacro(InteractiveUpdateRate, double, 1.0e-4, VTK_DOUBLE_MAX);
  vtkGetMacro(InteractiveUpdateRate, double);
  ///@}

  ///@{
  /**
   * Set/get the largest image sample distance (pixels between rays, each
   * way) of an interactive CPU frame: the floor of its resolution when the
   * frame cannot fit in the time the window allows. 1 turns progressive
   * refinement off. Default is 16 (a 1024 x 768 view drawn from 64 x 48
   * rays where a full frame takes seconds).
   */
  vtkSetClampMacro(MaximumImageSampleDistance, int, 1, 64);
  vtkGetMacro(MaximumImageSampleDistance, int);
  ///@}

  /// Pixels between rays (each way) in the last frame: 1 at full resolution.
  vtkGetMacro(LastImageSampleDistance, int);

  void Render(vtkRenderer* renderer, vtkVolume* volume) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkVolumeCutVolumeMapper();
  ~vtkVolumeCutVolumeMapper() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;

  /// Casts the rays on the CPU, one per sampleDistance^2 pixels, and draws the image.
  bool RenderOnCPU(vtkRenderer* renderer, vtkMatrix4x4* worldToNDC, int width, int height, const std::vector<float>& opaqueDepth,
    int sampleDistance);
  /// Draws the CPU image over the viewport, filtered where it is magnified;
  /// scale: the share of the image that covers it (below 1 where a reduced
  /// image's last block reaches past the viewport's edge).
  bool DrawCPUImage(int width, int height, bool magnified, double scaleX, double scaleY);
  /// The image sample distance for this frame: 1 unless interactive.
  int ChooseImageSampleDistance(vtkRenderer* renderer, int width, int height);

  int RequestedRenderPath = AutomaticPath;
  int LastRenderPath = 0;
  double LastFrameTime = 0.0;
  double InteractiveUpdateRate = 1.0;
  int MaximumImageSampleDistance = 16;
  int LastImageSampleDistance = 1;

private:
  vtkVolumeCutVolumeMapper(const vtkVolumeCutVolumeMapper&) = delete;
  void operator=(const vtkVolumeCutVolumeMapper&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
