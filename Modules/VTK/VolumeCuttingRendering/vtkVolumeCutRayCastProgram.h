// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutRayCastProgram
 * @brief   vtkVolumeCutOpenGLRayCaster's GLSL program for the features in use: its build, time limit, quad and uniforms.
 *
 * Ready() composes the fragment shader for the features
 * (vtkVolumeCutShaderComposer) and has vtkVolumeCutProgramBuilder build it
 * when they changed, then reports where the build stands as the caster's
 * ProgramStatuses. A build (or a wait for one) longer than the time limit,
 * its first image included (TimeFirstDraw), times the GPU path out until
 * ClearTimeOut(). A failed build is not tried again until the features
 * change, so a rejecting driver costs one build. SetUniforms() hands the
 * program the camera, the scene's grid, shading and skipping settings and
 * the cut fields' grids.
 */
#ifndef vtkVolumeCutRayCastProgram_h
#define vtkVolumeCutRayCastProgram_h

#include "vtkVolumeCutProgramBuilder.h"
#include "vtkVolumeCutRayCaster.h"
#include "vtkVolumeCutShaderComposer.h"

#include <vtkOpenGLVertexArrayObject.h> // For GetQuad
#include <vtkSmartPointer.h>
#include <vtkType.h>

#include <string>

class vtkMatrix4x4;
class vtkObject;
class vtkOpenGLRenderWindow;
class vtkShaderProgram;
class vtkVolumeCutSceneTextures;
class vtkWindow;

class vtkVolumeCutRayCastProgram
{
public:
  vtkVolumeCutRayCastProgram();
  ~vtkVolumeCutRayCastProgram();
  vtkVolumeCutRayCastProgram(const vtkVolumeCutRayCastProgram&) = delete;
  void operator=(const vtkVolumeCutRayCastProgram&) = delete;

  /**
   * Have the program for \a features built in window's context (current)
   * and bound, with its quad. Returns a vtkVolumeCutOpenGLRayCaster
   * ProgramStatuses value: ProgramReady when it draws, else
   * GetErrorMessage() says why not. The build may take \a timeLimit
   * seconds; binaries are cached in \a cacheDirectory (empty: the default
   * folder) where \a cache is on. \a caller reports a refused cache file,
   * once; \a driver names the driver in the messages.
   */
  int Ready(vtkObject* caller, vtkOpenGLRenderWindow* window, const vtkVolumeCutShaderComposer::Features& features,
    double timeLimit, bool cache, const std::string& cacheDirectory, const std::string& driver);

  /**
   * Call after the first draw of a new program, \a drawStart
   * (vtkTimerLog::GetUniversalTime()) before it: drivers may compile the
   * machine code at the first draw (llvmpipe does, for seconds), so the
   * build ends when the first image is done. Over \a timeLimit the GPU
   * path is off from the next frame. Does nothing after the first draw.
   */
  void TimeFirstDraw(double drawStart, double timeLimit, const std::string& driver);

  /**
   * Set the program's uniforms for \a view of \a scene seen through
   * \a worldToNDC in a width x height viewport, with \a textures uploaded.
   * emptySpaceSkipping: see vtkVolumeCutOpenGLRayCaster::EmptySpaceSkipping.
   */
  void SetUniforms(const vtkVolumeCutRayCaster::SceneView& view, vtkVolumeCutRayCaster* scene, vtkMatrix4x4* worldToNDC, int width,
    int height, const vtkVolumeCutSceneTextures& textures, bool emptySpaceSkipping);

  /// The program Ready() bound (nullptr before), and the full-viewport quad it draws.
  vtkShaderProgram* GetProgram() const { return this->QuadProgram; }
  vtkOpenGLVertexArrayObject* GetQuad() const { return this->QuadVAO; }

  /// Why the last Ready() did not give ProgramReady.
  const std::string& GetErrorMessage() const { return this->ErrorMessage; }

  /// Why the GPU path is off after a build over the time limit; empty while it is not.
  const std::string& GetTimedOutMessage() const { return this->TimedOutMessage; }
  /// Let the GPU path try once more.
  void ClearTimeOut() { this->TimedOutMessage.clear(); }

  /// The features and extra declarations of the program asked for: another key, another program.
  const std::string& GetKey() const { return this->BuiltFeatures; }

  ///@{
  /// See vtkVolumeCutOpenGLRayCaster: LastProgramBuildTime, LastProgramLoadedFromCache, ProgramSourceLength, ProgramFeatures.
  double GetBuildSeconds() const { return this->BuildSeconds; }
  bool GetLoadedFromCache() const { return this->LoadedFromCache; }
  vtkIdType GetSourceLength() const { return this->SourceLength; }
  const std::string& GetFeatures() const { return this->Features; }
  ///@}

  /// Delete the program and its quad; a build under way dies with its context.
  void Release(vtkWindow* window);

  /// "2.50 s": seconds as the messages give them.
  static std::string Seconds(double value);

private:
  vtkVolumeCutProgramBuilder Builder;
  std::string BuiltFeatures;
  bool BuildChecked = false;
  bool FirstDrawTimed = false;
  vtkSmartPointer<vtkOpenGLVertexArrayObject> QuadVAO;
  vtkShaderProgram* QuadProgram = nullptr;
  // Set when a build exceeded the time limit: the GPU path stays off.
  std::string TimedOutMessage;
  std::string ReportedCacheWarning;
  std::string ErrorMessage;
  double BuildSeconds = 0.0;
  bool LoadedFromCache = false;
  vtkIdType SourceLength = 0;
  std::string Features;
};

#endif
