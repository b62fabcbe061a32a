// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
/**
 * @class   vtkVolumeCutOpenGLRayCaster
 * @brief   GPU (OpenGL/GLSL) implementation of vtkVolumeCutRayCaster's algorithm.
 *
 * Draws one full-viewport quad whose fragment shader casts the pixel's ray
 * through the scene prepared by a vtkVolumeCutRayCaster: the CT and labels as
 * 3D textures (16-bit or 8-bit where lossless, see NormalizedTextures), the
 * labels fetched texel by texel, the CT and fractions filtered by the
 * texture unit where 16-bit (see HardwareFiltering), by the CPU's trilinear
 * arithmetic otherwise; each cut field as a page table (one texel a brick) and an atlas of
 * 8^3 bricks in which only bricks modified since the last frame are
 * re-uploaded (vtkVolumeCutField's modification stamps). It writes colour
 * (premultiplied) and the depth of the first visible surface.
 *
 * The image is cast into a framebuffer of this object's, sized to the
 * viewport, and drawn from there into the window: when only cut fields
 * changed since the last image (same camera, opaque depth, scene, program
 * and viewport size, as for the CPU path's localized updates), only the
 * rectangle over the bricks modified since then is recast (scissored), and
 * the rest of the kept image is drawn again as it was.
 *
 * Render() returns false with GetLastErrorMessage() set, and draws nothing,
 * when the context cannot run it (shader does not compile, volume larger than
 * the 3D texture limit, too many cut fields, texture allocation failed); the
 * caller then uses the CPU reference.
 *
 * The program is built for the features in use (vtkVolumeCutShaderComposer)
 * without blocking the view where the driver compiles in parallel
 * (GL_KHR_parallel_shader_compile): while GetProgramStatus() is
 * ProgramPending, Render() returns false and the caller draws the CPU image.
 * A build (or a wait for one) longer than ProgramBuildTimeLimit gives
 * ProgramTimedOut, and the GPU path stays off until the limit is set again.
 * Programs are kept on disk as driver binaries (ProgramCacheDirectory) so a
 * second start needs no compilation.
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
class vtkOpenGLVertexArrayObject;
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

  enum ProgramStatuses
  {
    ProgramNone = 0,     ///< no program asked for yet
    ProgramPending = 1,  ///< the driver is compiling it (parallel compile)
    ProgramReady = 2,    ///< built: Render draws
    ProgramFailed = 3,   ///< the driver rejected it (GetLastErrorMessage says why)
    ProgramTimedOut = 4  ///< its build exceeded ProgramBuildTimeLimit
  };

  /// The state of the program for the last Render's features.
  vtkGetMacro(ProgramStatus, int);

  ///@{
  /**
   * Set/get the longest a program build may take, in seconds, before the GPU
   * path gives way to the CPU (ProgramTimedOut): a build that blocks longer,
   * or a parallel build not finished by then. Setting it again (any value)
   * lets the GPU path try once more. Default is 10.
   */
  void SetProgramBuildTimeLimit(double seconds);
  vtkGetMacro(ProgramBuildTimeLimit, double);
  ///@}

  ///@{
  /**
   * Set/get the folder of cached program binaries. Empty (the default) means
   * DefaultProgramCacheDirectory(); the cache is used where the driver offers
   * a binary format (GL_NUM_PROGRAM_BINARY_FORMATS > 0) and ProgramCache is on.
   */
  vtkSetStdStringFromCharMacro(ProgramCacheDirectory);
  vtkGetCharFromStdStringMacro(ProgramCacheDirectory);
  ///@}

  ///@{
  /** Set/get whether program binaries are cached on disk. Default is true. */
  vtkSetMacro(ProgramCache, bool);
  vtkGetMacro(ProgramCache, bool);
  vtkBooleanMacro(ProgramCache, bool);
  ///@}

  /// $XDG_CACHE_HOME (or ~/.cache, %LOCALAPPDATA%) /VolumeCutting/programs.
  static std::string DefaultProgramCacheDirectory();

  ///@{
  /**
   * Set/get GLSL added to the fragment shader before main() (empty by
   * default): helper functions for instrumenting the program. A change
   * builds a new program; code the driver rejects gives ProgramFailed (the
   * tests use this to make a driver reject the program).
   */
  vtkSetStdStringFromCharMacro(ExtraFragmentDeclarations);
  vtkGetCharFromStdStringMacro(ExtraFragmentDeclarations);
  ///@}

  /**
   * Seconds the last program build took: compile and link (or loading the
   * cached binary) and its first image, as drivers may compile the machine
   * code at the first draw; the time so far while pending.
   */
  vtkGetMacro(LastProgramBuildTime, double);

  /// Whether the last program came from the on-disk cache.
  vtkGetMacro(LastProgramLoadedFromCache, bool);

  /// Characters of the last program's fragment shader (its size for the features in use).
  vtkGetMacro(ProgramSourceLength, vtkIdType);

  /// The features the last program was built for ("cuts=1 labels iso ...").
  const char* GetProgramFeatures() const { return this->ProgramFeatures.c_str(); }

  /// The OpenGL driver of the last Render: GL_RENDERER, GL_VERSION and GL_VENDOR.
  const char* GetDriverDescription() const { return this->DriverDescription.c_str(); }

  /// Whether the last Render's context compiles in parallel; its number of program binary formats.
  vtkGetMacro(ParallelCompile, bool);
  vtkGetMacro(NumberOfProgramBinaryFormats, int);

  /// Bricks of cut fields uploaded by the last Render, and in total.
  vtkGetMacro(NumberOfBricksUploaded, vtkIdType);
  vtkGetMacro(TotalNumberOfBricksUploaded, vtkIdType);

  ///@{
  /**
   * Set/get whether a frame in which only cut fields changed recasts only
   * the rectangle over the modified bricks. Off, every frame recasts the
   * whole viewport (the reference the localized image equals). Default is on.
   */
  vtkSetMacro(LocalizedUpdates, bool);
  vtkGetMacro(LocalizedUpdates, bool);
  vtkBooleanMacro(LocalizedUpdates, bool);
  ///@}

  ///@{
  /**
   * Set/get whether rays skip empty space as the CPU path does: through
   * cells where no visible object can be (to the last sample of the ray's
   * grid before one that may hold it), across the cube of empty blocks
   * around a sample, across the removed depth deep in a cavity, and with the
   * exact test of whether the CT reaches the iso-value between two samples
   * before an interval is refined. Off, rays jump one empty block at a time
   * and refine where the block's gradient bound allows a border (the GPU
   * path before; to measure what the skipping saves). Default is on.
   */
  vtkSetMacro(EmptySpaceSkipping, bool);
  vtkGetMacro(EmptySpaceSkipping, bool);
  vtkBooleanMacro(EmptySpaceSkipping, bool);
  ///@}

  /// Whether the last successful Render recast only the rectangle of modified bricks.
  vtkGetMacro(LastRenderWasLocalized, bool);

  /// Pixels the last successful Render recast (the viewport's, or its rectangle's; 0 when nothing changed).
  vtkGetMacro(NumberOfPixelsRecast, vtkIdType);

  /// Viewport rectangle (x0, y0, x1, y1, inclusive) the last Render recast; empty (x1 < x0) when none.
  vtkGetVector4Macro(UpdatedRegion, int);

  /// GPU memory (bytes) held by this object's textures.
  size_t GetTextureMemorySize() const;

  ///@{
  /**
   * Set/get whether the CT, the label map and fractional labelmaps may be
   * uploaded as unsigned normalized integer textures: half the memory and
   * bandwidth of floats or less. Where that loses nothing: the CT as R16
   * (value - minimum) when each value is the minimum plus an integer 0..65535
   * (integers spanning at most 65536 values, or such integers all shifted
   * by one offset), R32F otherwise; the labels as R8 (labels up to 255) or
   * R16. For both the shader reads the very floats it read from R32F.
   * Fractions (0..1, one segment a channel) as RGBA16, each within 1/131070
   * of its value. Cut fields' atlases as R16 (their distances are whole
   * quanta, stored + 32768), exact. Off keeps all of them float (to compare). Default is true; a change uploads them again at the
   * next Render.
   */
  vtkSetMacro(NormalizedTextures, bool);
  vtkGetMacro(NormalizedTextures, bool);
  vtkBooleanMacro(NormalizedTextures, bool);
  ///@}

  ///@{
  /**
   * Set/get whether the texture unit interpolates the CT and the fractions
   * (GL_LINEAR, one filtered fetch at the cell-centred coordinate
   * (index + 0.5) / dimensions) instead of the shader (eight texel fetches
   * and seven lerps in float). Used only where those textures are 16-bit
   * normalized: the CT as R16 (see NormalizedTextures), fractions as RGBA16;
   * a CT kept as R32F and the labels are always fetched texel by texel.
   *
   * Accuracy: texture units weight texels with fixed-point fractions,
   * commonly of 8 bits (Direct3D's sub-texel precision; NVIDIA's CUDA guide
   * gives 9-bit weights with 8 fraction bits, rounded to the nearest 1/256;
   * Vulkan reports it as subTexelPrecisionBits), so the filtered value is the
   * CPU's trilinear value at a point moved by at most 2^-9 voxel along each
   * axis: an iso-surface moves by at most sqrt(3) 2^-9 = 0.0034 voxel
   * whatever the CT's contrast (0.03 pixel at 8 pixels a voxel, far inside
   * the mapper tests' half-pixel edges), and each sample of a normal's
   * central differences (GradientStep h voxels each way) by at most the
   * gradient's length times sqrt(3) 2^-9: the normal turns by at most
   * 3 2^-9 / h radians (0.34 degrees at h = 1), its diffuse shade by at most
   * 1.5/255. Measured with EmulatedFilterWeightBits 8: colour within the
   * CPU/GPU tolerance (2/255 on 99.5 % of the pixels), a sphere's error
   * unchanged (radial RMS 0.0194 voxel, depth RMS 0.0246), but the depth
   * differs from the CPU's by more
   * than 1e-4 of the window range on 38 % of the pixels of a close-up (8
   * pixels a voxel) and at silhouettes; hence MaximumFilterWeightError.
   * A float-weight unit (Mesa's llvmpipe) gives the exact path's image.
   * Default is true; a change takes effect at the next Render.
   */
  vtkSetMacro(HardwareFiltering, bool);
  vtkGetMacro(HardwareFiltering, bool);
  vtkBooleanMacro(HardwareFiltering, bool);
  ///@}

  ///@{
  /**
   * Set/get the largest interpolation error of the texture unit, as a
   * fraction of the difference between two texels, at which
   * HardwareFiltering is used. The first Render in a context measures it
   * (GetFilterWeightError). The default, 2^-16, filters where the unit
   * interpolates about as finely as the 16-bit texels resolve (Mesa's
   * llvmpipe: float weights, 1e-7) and keeps the texel-by-texel path on GPUs
   * with 8-bit weights (2^-9): there a surface moves by up to 0.0034 voxel,
   * more than the CPU/GPU depth tolerance in close-ups (Docs/Architecture.md).
   * 2^-9 or more lets such GPUs filter.
   */
  vtkSetClampMacro(MaximumFilterWeightError, double, 0.0, 1.0);
  vtkGetMacro(MaximumFilterWeightError, double);
  ///@}

  /**
   * The texture unit's interpolation error measured in the last Render's
   * context: the largest difference, over 1021 points, between GL_LINEAR
   * between two R16 texels 0 and 65535 and the exact lerp, a fraction of
   * their difference. -1 before it was measured, or where the driver cannot
   * filter R16 (the CT and fractions are then fetched texel by texel).
   */
  vtkGetMacro(FilterWeightError, double);

  ///@{
  /**
   * Whether the last Render's program sampled the CT, or the fractions,
   * with the texture unit's filtering (HardwareFiltering on, the texture
   * 16-bit normalized, and the unit's FilterWeightError within
   * MaximumFilterWeightError); false before the first Render.
   */
  vtkGetMacro(AnatomyHardwareFiltered, bool);
  vtkGetMacro(FractionsHardwareFiltered, bool);
  ///@}

  ///@{
  /**
   * Set/get, for accuracy tests, the fractional bits to which the shader's
   * own trilinear interpolation of the CT and the fractions rounds its
   * weights (0, the default: float weights). 8 gives, on any driver, what
   * a texture unit with 8-bit weights would filter; it applies where
   * HardwareFiltering is not in use (turn that off to see it).
   */
  vtkSetClampMacro(EmulatedFilterWeightBits, int, 0, 16);
  vtkGetMacro(EmulatedFilterWeightBits, int);
  ///@}

  ///@{
  /**
   * Bytes a voxel of the CT texture, the label texture and the fractions'
   * texture take on the GPU, as the driver reports them for the last upload
   * (GL_TEXTURE_RED_SIZE): 2 for R16, 4 for R32F, 1 for R8, 8 for RGBA16,
   * 16 for RGBA32F; 0 before the first upload or without such data.
   */
  vtkGetMacro(AnatomyTextureBytesPerVoxel, int);
  vtkGetMacro(LabelTextureBytesPerVoxel, int);
  vtkGetMacro(FractionTextureBytesPerVoxel, int);
  ///@}

  /**
   * Bytes a texel of the first cut field's brick atlas takes on the GPU: 2
   * for R16, 4 for R32F; 0 without a cut field.
   */
  vtkGetMacro(CutAtlasTextureBytesPerVoxel, int);

  /// Texels of all cut fields' brick atlases (they grow by half again when full).
  vtkIdType GetCutAtlasTextureSize() const;

  void ReleaseGraphicsResources(vtkWindow* window);

  /**
   * Draw a full-viewport quad whose fragments carry premultiplied colour and
   * gl_FragDepth: blended over the framebuffer, writing depth (the state is
   * restored after). Both paths draw their images this way.
   */
  static void DrawSurfaceQuad(vtkOpenGLRenderWindow* window, vtkOpenGLQuadHelper* quad);
  static void DrawSurfaceQuad(vtkOpenGLRenderWindow* window, vtkOpenGLVertexArrayObject* quad);

protected:
  vtkVolumeCutOpenGLRayCaster();
  ~vtkVolumeCutOpenGLRayCaster() override;

  std::string LastErrorMessage;
  int ProgramStatus = ProgramNone;
  double ProgramBuildTimeLimit = 10.0;
  std::string ProgramCacheDirectory;
  bool ProgramCache = true;
  std::string ExtraFragmentDeclarations;
  double LastProgramBuildTime = 0.0;
  bool LastProgramLoadedFromCache = false;
  vtkIdType ProgramSourceLength = 0;
  std::string ProgramFeatures;
  std::string DriverDescription;
  bool ParallelCompile = false;
  int NumberOfProgramBinaryFormats = 0;
  vtkIdType NumberOfBricksUploaded = 0;
  vtkIdType TotalNumberOfBricksUploaded = 0;
  bool NormalizedTextures = true;
  int AnatomyTextureBytesPerVoxel = 0;
  int LabelTextureBytesPerVoxel = 0;
  int FractionTextureBytesPerVoxel = 0;
  int CutAtlasTextureBytesPerVoxel = 0;
  bool HardwareFiltering = true;
  bool AnatomyHardwareFiltered = false;
  bool FractionsHardwareFiltered = false;
  int EmulatedFilterWeightBits = 0;
  double MaximumFilterWeightError = 1.0 / 65536.0;
  double FilterWeightError = -1.0;
  bool LocalizedUpdates = true;
  bool EmptySpaceSkipping = true;
  bool LastRenderWasLocalized = false;
  vtkIdType NumberOfPixelsRecast = 0;
  int UpdatedRegion[4] = { 0, 0, -1, -1 };

private:
  vtkVolumeCutOpenGLRayCaster(const vtkVolumeCutOpenGLRayCaster&) = delete;
  void operator=(const vtkVolumeCutOpenGLRayCaster&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
