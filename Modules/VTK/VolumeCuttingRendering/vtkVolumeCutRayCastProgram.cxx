// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutRayCastProgram.h"

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutOpenGLRayCaster.h"
#include "vtkVolumeCutSceneTextures.h"

#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkOpenGLRenderUtilities.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLShaderCache.h>
#include <vtkOpenGLVertexArrayObject.h>
#include <vtkShaderProgram.h>
#include <vtkTimerLog.h>
#include <vtk_glad.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace
{
void ColumnMajor(const double rowMajor[16], float out[16])
{
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      out[column * 4 + row] = static_cast<float>(rowMajor[row * 4 + column]);
    }
  }
}
}

//------------------------------------------------------------------------------
vtkVolumeCutRayCastProgram::vtkVolumeCutRayCastProgram() = default;

//------------------------------------------------------------------------------
vtkVolumeCutRayCastProgram::~vtkVolumeCutRayCastProgram() = default;

//------------------------------------------------------------------------------
std::string vtkVolumeCutRayCastProgram::Seconds(double value)
{
  std::ostringstream text;
  text << std::fixed << std::setprecision(value < 10.0 ? 2 : 1) << value << " s";
  return text.str();
}

//------------------------------------------------------------------------------
int vtkVolumeCutRayCastProgram::Ready(vtkObject* caller, vtkOpenGLRenderWindow* window,
  const vtkVolumeCutShaderComposer::Features& features, double timeLimit, bool cache, const std::string& cacheDirectory,
  const std::string& driver)
{
  auto seconds = &vtkVolumeCutRayCastProgram::Seconds;
  if (!this->TimedOutMessage.empty())
  {
    this->ErrorMessage = this->TimedOutMessage;
    return vtkVolumeCutOpenGLRayCaster::ProgramTimedOut;
  }
  const std::string key = vtkVolumeCutShaderComposer::Describe(features) + '\n' + features.ExtraDeclarations;
  if (key != this->BuiltFeatures || this->Builder.GetStatus() == vtkVolumeCutProgramBuilder::Empty)
  {
    // Other features: another program (a failed one is not tried again
    // until the features change, so a rejecting driver costs one build).
    const std::string fragment = vtkVolumeCutShaderComposer::FragmentShader(features);
    this->SourceLength = static_cast<vtkIdType>(fragment.size());
    this->Features = vtkVolumeCutShaderComposer::Describe(features);
    this->BuiltFeatures = key;
    this->BuildChecked = false;
    this->FirstDrawTimed = false;
    this->QuadProgram = nullptr;
    std::string directory;
    if (cache)
    {
      directory = cacheDirectory.empty() ? vtkVolumeCutOpenGLRayCaster::DefaultProgramCacheDirectory() : cacheDirectory;
    }
    this->Builder.Start(window, vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader(), fragment, directory);
  }
  const vtkVolumeCutProgramBuilder::Status status = this->Builder.Poll();
  if (!this->FirstDrawTimed)
  {
    this->BuildSeconds = this->Builder.GetBuildSeconds();
  }
  this->LoadedFromCache = this->Builder.GetLoadedFromCache();
  const std::string& cacheWarning = this->Builder.GetCacheWarning();
  if (!cacheWarning.empty() && cacheWarning != this->ReportedCacheWarning)
  {
    // Once: the program is rebuilt from source and stored again.
    vtkWarningWithObjectMacro(caller, "Render: " << cacheWarning);
    this->ReportedCacheWarning = cacheWarning;
  }
  const std::string limit = seconds(timeLimit);
  switch (status)
  {
    case vtkVolumeCutProgramBuilder::Pending:
      if (this->BuildSeconds <= timeLimit)
      {
        this->ErrorMessage = "the GPU program is being built (" + seconds(this->BuildSeconds) + " so far, limit " + limit + ")";
        return vtkVolumeCutOpenGLRayCaster::ProgramPending;
      }
      this->TimedOutMessage = "the GPU program was not built after " + seconds(this->BuildSeconds) + " on " + driver +
        ", over ProgramBuildTimeLimit (" + limit + "); cuts are drawn on the CPU";
      this->Builder.Release(window);
      this->ErrorMessage = this->TimedOutMessage;
      return vtkVolumeCutOpenGLRayCaster::ProgramTimedOut;
    case vtkVolumeCutProgramBuilder::Failed:
      this->ErrorMessage =
        "the OpenGL driver (" + driver + ") rejects the GPU program (" + this->Features + "): " + this->Builder.GetError();
      return vtkVolumeCutOpenGLRayCaster::ProgramFailed;
    case vtkVolumeCutProgramBuilder::Ready:
      break;
    default:
      this->ErrorMessage = "no GPU program";
      return vtkVolumeCutOpenGLRayCaster::ProgramNone;
  }
  if (!this->BuildChecked)
  {
    this->BuildChecked = true;
    if (this->BuildSeconds > timeLimit)
    {
      // The build blocked the view for longer than allowed: the next one
      // (other features, another start without the cache) would too.
      this->TimedOutMessage = std::string(this->LoadedFromCache ? "loading" : "building") + " the GPU program took " +
        seconds(this->BuildSeconds) + " on " + driver + ", over ProgramBuildTimeLimit (" + limit + "); cuts are drawn on the CPU";
      this->Builder.Release(window);
      this->ErrorMessage = this->TimedOutMessage;
      return vtkVolumeCutOpenGLRayCaster::ProgramTimedOut;
    }
  }
  vtkShaderProgram* program = this->Builder.GetProgram();
  window->GetShaderCache()->ReadyShaderProgram(program);
  if (this->QuadProgram != program || !this->QuadVAO)
  {
    if (!this->QuadVAO)
    {
      this->QuadVAO = vtkSmartPointer<vtkOpenGLVertexArrayObject>::New();
    }
    this->QuadVAO->ReleaseGraphicsResources();
    if (!vtkOpenGLRenderUtilities::PrepFullScreenVAO(window, this->QuadVAO, program))
    {
      this->ErrorMessage = "the full-screen quad cannot be set up for the GPU program";
      return vtkVolumeCutOpenGLRayCaster::ProgramFailed;
    }
    this->QuadProgram = program;
  }
  this->ErrorMessage.clear();
  return vtkVolumeCutOpenGLRayCaster::ProgramReady;
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCastProgram::TimeFirstDraw(double drawStart, double timeLimit, const std::string& driver)
{
  if (this->FirstDrawTimed)
  {
    return;
  }
  glFinish();
  this->FirstDrawTimed = true;
  this->BuildSeconds += vtkTimerLog::GetUniversalTime() - drawStart;
  if (this->BuildSeconds > timeLimit)
  {
    this->TimedOutMessage = "building the GPU program and its first image took " + Seconds(this->BuildSeconds) + " on " + driver +
      ", over ProgramBuildTimeLimit (" + Seconds(timeLimit) + "); cuts are drawn on the CPU from the next frame";
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCastProgram::SetUniforms(const vtkVolumeCutRayCaster::SceneView& view, vtkVolumeCutRayCaster* scene,
  vtkMatrix4x4* worldToNDC, int width, int height, const vtkVolumeCutSceneTextures& textures, bool emptySpaceSkipping)
{
  vtkShaderProgram* program = this->QuadProgram;
  vtkVolumeCutRayCaster* s = scene;
  const int* dims = view.Dimensions;
  float matrix[16];
  double ndcToWorld[16];
  double worldToNDCValues[16];
  {
    vtkNew<vtkMatrix4x4> inverse;
    vtkMatrix4x4::Invert(worldToNDC, inverse);
    std::copy(&inverse->Element[0][0], &inverse->Element[0][0] + 16, ndcToWorld);
    std::copy(&worldToNDC->Element[0][0], &worldToNDC->Element[0][0] + 16, worldToNDCValues);
  }
  ColumnMajor(ndcToWorld, matrix);
  program->SetUniformMatrix4x4("ndcToWorld", matrix);
  ColumnMajor(worldToNDCValues, matrix);
  program->SetUniformMatrix4x4("worldToNDC", matrix);
  ColumnMajor(view.WorldToIJK, matrix);
  program->SetUniformMatrix4x4("worldToIJK", matrix);
  ColumnMajor(view.IJKToWorld, matrix);
  program->SetUniformMatrix4x4("ijkToWorld", matrix);
  float normal3[9];
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      normal3[column * 3 + row] = static_cast<float>(view.NormalMatrix[row * 4 + column]);
    }
  }
  program->SetUniformMatrix3x3("normalMatrix", normal3);
  const float dimensions[3] = { float(dims[0]), float(dims[1]), float(dims[2]) };
  program->SetUniform3f("dimensionsF", dimensions);
  float millimetresPerIndex[3];
  for (int axis = 0; axis < 3; ++axis)
  {
    const double* row = view.WorldToIJK + 4 * axis;
    millimetresPerIndex[axis] = static_cast<float>(1.0 / std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]));
  }
  program->SetUniform3f("millimetresPerIndex", millimetresPerIndex);
  const float blockDimensions[3] = { float(view.BlockDimensions[0]), float(view.BlockDimensions[1]), float(view.BlockDimensions[2]) };
  program->SetUniform3f("blockDimensionsF", blockDimensions);
  const float size[2] = { float(width), float(height) };
  program->SetUniform2f("viewportSize", size);
  program->SetUniformi("hasLabels", view.Labels || !view.Fractions.empty() ? 1 : 0);
  program->SetUniformi("hasLabelMap", view.Labels ? 1 : 0);
  program->SetUniformf("anatomyMinimum", textures.GetAnatomyMinimum());
  program->SetUniformf("labelScale", textures.GetLabelScale());
  program->SetUniformi("fractionCount", static_cast<int>(view.Fractions.size()));
  float fractionLabels[4] = { 0.f, 0.f, 0.f, 0.f };
  for (size_t i = 0; i < view.Fractions.size(); ++i)
  {
    fractionLabels[i] = static_cast<float>(view.Fractions[i].first);
  }
  program->SetUniform4f("fractionLabels", fractionLabels);
  program->SetUniformi("styleCount", static_cast<int>(view.Styles.size()));
  program->SetUniformf("sampleDistance", static_cast<float>(s->GetSampleDistance()));
  program->SetUniformf("gradientStep", static_cast<float>(s->GetGradientStep()));
  program->SetUniformf("ambientK", static_cast<float>(s->GetAmbient()));
  program->SetUniformf("diffuseK", static_cast<float>(s->GetDiffuse()));
  program->SetUniformf("specularK", static_cast<float>(s->GetSpecular()));
  program->SetUniformf("specularPower", static_cast<float>(s->GetSpecularPower()));
  program->SetUniformi("anyIso", view.AnyIsoSegment ? 1 : 0);
  program->SetUniformf("minimumIso", static_cast<float>(std::isfinite(view.MinimumIso) ? view.MinimumIso : 1e30));
  program->SetUniformi("blendMode", s->GetBlendMode());
  program->SetUniformf("unitDistance", static_cast<float>(s->GetScalarOpacityUnitDistance()));
  const float range[2] = { float(view.TableRange[0]), float(view.TableRange[1]) };
  program->SetUniform2f("tableRange", range);
  program->SetUniformi("tableSize", std::max(view.TableSize, 2));
  program->SetUniformi("thinBone", s->GetThinBoneShading() ? 1 : 0);
  program->SetUniformf("thinBoneThickness", static_cast<float>(s->GetThinBoneThickness()));
  program->SetUniformi("ambientOcclusion", s->GetAmbientOcclusion() && s->GetBlendMode() == vtkVolumeCutRayCaster::IsoSurfaceBlend ? 1 : 0);
  program->SetUniformf("ambientOcclusionRadius", static_cast<float>(s->GetAmbientOcclusionRadius()));
  program->SetUniformi("refinements", view.MaximumRefinements);
  program->SetUniformi("bisectionSteps", 22);
  program->SetUniformi("cellWalk", textures.GetCellWalk() && emptySpaceSkipping ? 1 : 0);
  // A straight ray crosses fewer cells than the sum of the cell grid's sides.
  program->SetUniformi("cellWalkSteps", dims[0] + dims[1] + dims[2]);
  program->SetUniformi("reachJumps", emptySpaceSkipping ? 1 : 0);
  program->SetUniformi("exactHiddenBorders", emptySpaceSkipping ? 1 : 0);
  program->SetUniformi("cavityJumps", emptySpaceSkipping ? 1 : 0);
  // Cell pieces of one interval in the exact hidden-border test: a uniform
  // bound (a constant would have drivers unroll the loop).
  program->SetUniformi("intervalPieces", 16);
  program->SetUniformi("occlusionPoints", 14);
  const int planeCount = std::min(static_cast<int>(view.Planes.size()), 6);
  float planes[6][4] = {};
  for (int p = 0; p < planeCount; ++p)
  {
    for (int c = 0; c < 4; ++c)
    {
      planes[p][c] = static_cast<float>(view.Planes[p][c]);
    }
  }
  program->SetUniformi("planeCount", planeCount);
  program->SetUniform4fv("planes", 6, planes);

  const int cuts = static_cast<int>(view.CutFields.size());
  for (int n = 0; n < cuts; ++n)
  {
    const std::string index = std::to_string(n);
    const vtkVolumeCutBrickAtlas& atlas = textures.GetBrickAtlas(n);
    const int* cutDims = atlas.GetDimensions();
    const float cutDimensions[3] = { float(cutDims[0]), float(cutDims[1]), float(cutDims[2]) };
    program->SetUniform3f(("cutDimensionsF" + index).c_str(), cutDimensions);
    program->SetUniformi(("cutSlots" + index).c_str(), atlas.GetSlotsPerAxis());
    vtkVolumeCutField* field = view.CutFields[n];
    vtkNew<vtkMatrix4x4> subToWorld;
    field->GetSubVoxelIJKToRAS(subToWorld);
    vtkNew<vtkMatrix4x4> worldToSub;
    vtkMatrix4x4::Invert(subToWorld, worldToSub);
    ColumnMajor(&worldToSub->Element[0][0], matrix);
    program->SetUniformMatrix4x4(("worldToSub" + index).c_str(), matrix);
    program->SetUniformf(("cutQuantum" + index).c_str(), static_cast<float>(field->GetQuantum()));
    program->SetUniformf(
      ("cutCorrectionReach" + index).c_str(), static_cast<float>(field->GetCorrectionReach() / field->GetQuantum()));
    double spacing[3];
    field->GetSubVoxelSpacing(spacing);
    program->SetUniformf(("cutStep" + index).c_str(), static_cast<float>(0.25 * std::min({ spacing[0], spacing[1], spacing[2] })));
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutRayCastProgram::Release(vtkWindow* window)
{
  if (this->QuadVAO)
  {
    this->QuadVAO->ReleaseGraphicsResources();
    this->QuadVAO = nullptr;
  }
  this->QuadProgram = nullptr;
  // A build under way dies with its context; the next Ready starts again.
  this->Builder.Release(window);
  this->BuiltFeatures.clear();
}
