// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutProgramBuilder
 * @brief   Builds vtkVolumeCutOpenGLRayCaster's GLSL program without blocking the view where the driver allows.
 *
 * VTK's shader cache compiles and links in one blocking call. This builder
 * does the same steps (VTK's own System/Output replacements included) but:
 * - where the context has GL_KHR_parallel_shader_compile (or the ARB
 *   extension), Start() only submits the compile and link, and Poll() asks
 *   GL_COMPLETION_STATUS without waiting, so the caller keeps drawing
 *   another image until the program is ready;
 * - it keeps program binaries on disk (GL_ARB_get_program_binary, where the
 *   driver offers a binary format): the key is a hash of the full sources and
 *   of GL_VENDOR, GL_RENDERER, GL_VERSION and the GLSL version, so a second
 *   start of the same program on the same driver needs no compilation; a
 *   file that is unreadable, truncated, of another key or refused by the
 *   driver is ignored (GetCacheWarning() says why, once), removed and
 *   rebuilt from source;
 * - it measures the build (GetBuildSeconds(): from Start() to the program
 *   being ready).
 * The program becomes a vtkShaderProgram whose uniforms are set as usual.
 */
#ifndef vtkVolumeCutProgramBuilder_h
#define vtkVolumeCutProgramBuilder_h

#include <vtkSmartPointer.h>

#include <string>

class vtkOpenGLRenderWindow;
class vtkShaderProgram;
class vtkWindow;

class vtkVolumeCutProgramBuilder
{
public:
  enum Status
  {
    Empty,   ///< nothing started
    Pending, ///< submitted; the driver is still compiling
    Ready,   ///< linked: GetProgram() draws
    Failed   ///< rejected by the driver: GetError() says why
  };

  vtkVolumeCutProgramBuilder();
  ~vtkVolumeCutProgramBuilder();
  vtkVolumeCutProgramBuilder(const vtkVolumeCutProgramBuilder&) = delete;
  void operator=(const vtkVolumeCutProgramBuilder&) = delete;

  /**
   * Start building the program of these sources in window's context (which
   * must be current), replacing any program held. cacheDirectory: where
   * binaries are kept ("" for none). Returns the status reached at once:
   * Ready when the binary came from the cache or the driver compiled without
   * parallel compile, Pending otherwise, or Failed.
   */
  Status Start(vtkOpenGLRenderWindow* window, const std::string& vertexSource, const std::string& fragmentSource,
    const std::string& cacheDirectory);

  /// Ask the driver whether a pending build finished; never waits where parallel compile exists.
  Status Poll();

  /// Whether the context compiles in parallel (GL_KHR/ARB_parallel_shader_compile).
  static bool HasParallelCompile();

  /// Binary formats the context offers (GL_NUM_PROGRAM_BINARY_FORMATS; 0: no cache possible).
  static int NumberOfBinaryFormats();

  /// "GL_RENDERER, OpenGL GL_VERSION (GL_VENDOR)" of the current context.
  static std::string DriverDescription();

  /// The default cache folder: $XDG_CACHE_HOME (or ~/.cache, %LOCALAPPDATA%) /VolumeCutting/programs.
  static std::string DefaultCacheDirectory();

  Status GetStatus() const { return this->State; }
  /// The linked program (nullptr unless Ready).
  vtkShaderProgram* GetProgram() const;
  /// The fragment source as given to Start (before VTK's replacements).
  const std::string& GetFragmentSource() const { return this->FragmentSource; }
  /// Seconds from Start to Ready or Failed; while Pending, the time so far.
  double GetBuildSeconds() const;
  /// Whether the program came from a cached binary.
  bool GetLoadedFromCache() const { return this->LoadedFromCache; }
  /// Whether the last ready program was written to the cache.
  bool GetStoredInCache() const { return this->StoredInCache; }
  /// The driver's compile or link log when Failed.
  const std::string& GetError() const { return this->Error; }
  /// Why a cache file was not used (empty if none was refused); cleared by Start.
  const std::string& GetCacheWarning() const { return this->CacheWarning; }

  /// Delete the program (the context must be current, or the window released already).
  void Release(vtkWindow* window);
  /// Forget the program without deleting it (its context is gone).
  void Abandon();

private:
  bool LoadBinary();
  void StoreBinary();
  Status Finish();
  std::string CacheFile() const;

  Status State = Empty;
  vtkOpenGLRenderWindow* Window = nullptr;
  vtkSmartPointer<vtkShaderProgram> Program;
  unsigned int Handle = 0;
  unsigned int VertexShader = 0;
  unsigned int FragmentShader = 0;
  std::string FragmentSource;
  std::string Key;
  std::string CacheDirectory;
  double StartTime = 0.0;
  double BuildSeconds = 0.0;
  bool LoadedFromCache = false;
  bool StoredInCache = false;
  std::string Error;
  std::string CacheWarning;
};

#endif
