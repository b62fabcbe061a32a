// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutOpenGLRayCaster.h"

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutFilterProbe.h"
#include "vtkVolumeCutKeptImage.h"
#include "vtkVolumeCutProgramBuilder.h"
#include "vtkVolumeCutRayCastProgram.h"
#include "vtkVolumeCutRayCaster.h"
#include "vtkVolumeCutSceneTextures.h"
#include "vtkVolumeCutShaderComposer.h"

#include <vtkMatrix4x4.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLQuadHelper.h>
#include <vtkOpenGLRenderUtilities.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkOpenGLVertexArrayObject.h>
#include <vtkTextureObject.h>
#include <vtkTimerLog.h>
#include <vtk_glad.h>

#include <algorithm>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutOpenGLRayCaster);

//------------------------------------------------------------------------------
// The GPU path's parts, each bound to the context of the last Render.
struct vtkVolumeCutOpenGLRayCaster::Internals
{
  vtkOpenGLRenderWindow* Context = nullptr;
  vtkVolumeCutSceneTextures Textures;
  vtkVolumeCutFilterProbe FilterProbe;
  vtkVolumeCutRayCastProgram Program;
  vtkVolumeCutKeptImage Kept;

  void Release(vtkWindow* window)
  {
    this->Textures.Release(window);
    this->Program.Release(window);
    this->Kept.Release(window);
    this->FilterProbe.Forget();
    this->Context = nullptr;
  }
};

//------------------------------------------------------------------------------
vtkVolumeCutOpenGLRayCaster::vtkVolumeCutOpenGLRayCaster()
  : Impl(new Internals)
{
}

//------------------------------------------------------------------------------
vtkVolumeCutOpenGLRayCaster::~vtkVolumeCutOpenGLRayCaster()
{
  if (this->Impl->Context)
  {
    this->Impl->Release(this->Impl->Context);
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutOpenGLRayCaster::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
}

//------------------------------------------------------------------------------
vtkIdType vtkVolumeCutOpenGLRayCaster::GetCutAtlasTextureSize() const
{
  return this->Impl->Textures.GetCutAtlasTexels();
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutOpenGLRayCaster::GetTextureMemorySize() const
{
  return this->Impl->Textures.GetMemorySize() + this->Impl->Kept.GetMemorySize();
}

//------------------------------------------------------------------------------
bool vtkVolumeCutOpenGLRayCaster::Render(vtkOpenGLRenderWindow* window, vtkVolumeCutRayCaster* scene, vtkMatrix4x4* worldToNDC,
  int vtkNotUsed(x0), int vtkNotUsed(y0), int width, int height, const float* opaqueDepth)
{
  this->LastErrorMessage.clear();
  this->NumberOfBricksUploaded = 0;
  this->LastRenderWasLocalized = false;
  this->NumberOfPixelsRecast = 0;
  this->UpdatedRegion[0] = this->UpdatedRegion[1] = 0;
  this->UpdatedRegion[2] = this->UpdatedRegion[3] = -1;
  Internals& impl = *this->Impl;
  if (!window || !scene || !worldToNDC || width < 1 || height < 1)
  {
    this->LastErrorMessage = "no OpenGL window, scene or camera";
    return false;
  }
  vtkVolumeCutRayCaster::SceneView view;
  if (!scene->UpdateScene(view))
  {
    this->LastErrorMessage = "the scene cannot be rendered (see the error above)";
    return false;
  }
  if (view.Fractions.size() > 4)
  {
    this->LastErrorMessage = "more than 4 segments with fractional labelmaps";
    return false;
  }
  const int cuts = static_cast<int>(view.CutFields.size());
  if (cuts > MaximumNumberOfCutFields)
  {
    this->LastErrorMessage = "more than " + std::to_string(MaximumNumberOfCutFields) + " cut fields";
    return false;
  }
  if (impl.Context && impl.Context != window)
  {
    impl.Release(impl.Context);
  }
  impl.Context = window;
  this->DriverDescription = vtkVolumeCutProgramBuilder::DriverDescription();
  this->ParallelCompile = vtkVolumeCutProgramBuilder::HasParallelCompile();
  this->NumberOfProgramBinaryFormats = vtkVolumeCutProgramBuilder::NumberOfBinaryFormats();
  vtkVolumeCutRayCastProgram& program = impl.Program;
  if (!program.GetTimedOutMessage().empty())
  {
    // Nothing to upload for a path that stays off.
    this->ProgramStatus = ProgramTimedOut;
    this->LastErrorMessage = program.GetTimedOutMessage();
    return false;
  }

  GLint maximum3D = 0;
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &maximum3D);
  const int* dims = view.Dimensions;
  if (dims[0] > maximum3D || dims[1] > maximum3D || dims[2] > maximum3D)
  {
    std::ostringstream message;
    message << "the volume (" << dims[0] << " x " << dims[1] << " x " << dims[2] << ") exceeds this GPU's 3D texture limit of "
            << maximum3D;
    this->LastErrorMessage = message.str();
    return false;
  }

  vtkVolumeCutSceneTextures& textures = impl.Textures;
  const bool sceneUploaded = textures.UpdateScene(window, view, this->NormalizedTextures);
  this->AnatomyTextureBytesPerVoxel = textures.GetAnatomyBytesPerVoxel();
  this->LabelTextureBytesPerVoxel = textures.GetLabelBytesPerVoxel();
  this->FractionTextureBytesPerVoxel = textures.GetFractionBytesPerVoxel();
  if (!sceneUploaded)
  {
    this->LastErrorMessage = textures.GetErrorMessage();
    return false;
  }

  // The counters before the upload: a brick stamped after them is recast next time.
  std::vector<vtkTypeUInt64> currentStamps(cuts);
  for (int n = 0; n < cuts; ++n)
  {
    currentStamps[n] = view.CutFields[n]->GetCurrentStamp();
  }
  // Cut fields: only modified bricks travel.
  if (!textures.UpdateCutFields(window, view.CutFields, this->NormalizedTextures, this->NumberOfBricksUploaded))
  {
    this->LastErrorMessage = textures.GetErrorMessage();
    return false;
  }
  this->TotalNumberOfBricksUploaded += this->NumberOfBricksUploaded;

  if (!textures.UpdateOpaqueDepth(window, opaqueDepth, width, height))
  {
    this->LastErrorMessage = textures.GetErrorMessage();
    return false;
  }

  vtkVolumeCutShaderComposer::Features features;
  features.CutFields = cuts;
  features.LabelMap = view.Labels != nullptr;
  features.Fractions = static_cast<int>(view.Fractions.size());
  features.Composite = scene->GetBlendMode() == vtkVolumeCutRayCaster::CompositeBlend;
  features.ThinBone = scene->GetThinBoneShading();
  features.AmbientOcclusion = scene->GetAmbientOcclusion() && !features.Composite;
  features.ClipPlanes = std::min(static_cast<int>(view.Planes.size()), 6);
  features.ExtraDeclarations = this->ExtraFragmentDeclarations;
  features.AnatomyUnorm16 = textures.GetAnatomyUnorm16();
  features.CutAtlasUnorm16.clear();
  for (int n = 0; n < cuts; ++n)
  {
    features.CutAtlasUnorm16.push_back(textures.GetBrickAtlas(n).GetUnorm16());
  }
  this->CutAtlasTextureBytesPerVoxel = cuts > 0 ? textures.GetBrickAtlas(0).GetBytesPerTexel() : 0;
  // Only 16-bit normalized textures are filtered (R32F is not filterable
  // everywhere: OES_texture_float_linear; labels are never interpolated),
  // and only by a texture unit that weights texels finely enough.
  if (this->HardwareFiltering && (textures.GetAnatomyUnorm16() || textures.GetFractionsUnorm16()))
  {
    impl.FilterProbe.MeasureOnce(window);
  }
  this->FilterWeightError = impl.FilterProbe.GetFilterWeightError();
  const bool precise =
    this->HardwareFiltering && this->FilterWeightError >= 0.0 && this->FilterWeightError <= this->MaximumFilterWeightError;
  this->AnatomyHardwareFiltered = precise && textures.GetAnatomyUnorm16();
  this->FractionsHardwareFiltered = precise && textures.GetFractionsUnorm16();
  textures.SetFiltering(this->AnatomyHardwareFiltered, this->FractionsHardwareFiltered);
  features.AnatomyFiltered = this->AnatomyHardwareFiltered;
  features.FractionsFiltered = this->FractionsHardwareFiltered;
  features.FilterWeightBits = this->EmulatedFilterWeightBits;
  this->ProgramStatus = program.Ready(this, window, features, this->ProgramBuildTimeLimit, this->ProgramCache,
    this->ProgramCacheDirectory, this->DriverDescription);
  this->LastProgramBuildTime = program.GetBuildSeconds();
  this->LastProgramLoadedFromCache = program.GetLoadedFromCache();
  this->ProgramSourceLength = program.GetSourceLength();
  this->ProgramFeatures = program.GetFeatures();
  if (this->ProgramStatus != ProgramReady)
  {
    this->LastErrorMessage = program.GetErrorMessage();
    return false;
  }
  program.SetUniforms(view, scene, worldToNDC, width, height, textures, this->EmptySpaceSkipping);
  std::vector<vtkTextureObject*> active;
  textures.Activate(program.GetProgram(), cuts, active);

  // The kept image is this frame's but where bricks changed when nothing
  // else did since it was cast (the CPU path's conditions for a localized update).
  vtkVolumeCutKeptImage::Source source;
  std::copy(&worldToNDC->Element[0][0], &worldToNDC->Element[0][0] + 16, source.WorldToNDC);
  source.SceneVersion = view.Version;
  source.AnatomyVersion = view.AnatomyVersion;
  source.LabelVersion = view.LabelVersion;
  source.ProgramKey = program.GetKey();
  source.EmptySpaceSkipping = this->EmptySpaceSkipping;
  source.OpaqueDepthVersion = textures.GetOpaqueDepthVersion();
  source.Fields = view.CutFields;
  source.Stamps = currentStamps;
  vtkVolumeCutKeptImage& kept = impl.Kept;
  const bool localized = this->LocalizedUpdates && kept.CastFrom(source, width, height);
  if (!kept.Reserve(window, width, height))
  {
    for (vtkTextureObject* texture : active)
    {
      texture->Deactivate();
    }
    this->LastErrorMessage = "no framebuffer for a " + std::to_string(width) + " x " + std::to_string(height) + " image on the GPU";
    return false;
  }
  int region[4] = { 0, 0, width - 1, height - 1 };
  if (localized)
  {
    const double reach = std::max(features.AmbientOcclusion ? scene->GetAmbientOcclusionRadius() : 0.0,
      features.ThinBone ? scene->GetThinBoneThickness() : 0.0);
    kept.GetModifiedRegion(source.WorldToNDC, width, height, reach, region);
  }
  kept.Invalidate(); // until the cast below is done

  const double drawStart = vtkTimerLog::GetUniversalTime();
  if (region[2] >= region[0] && region[3] >= region[1])
  {
    kept.Cast(window, region, program.GetQuad());
  }
  program.TimeFirstDraw(drawStart, this->ProgramBuildTimeLimit, this->DriverDescription);
  this->LastProgramBuildTime = program.GetBuildSeconds();
  for (vtkTextureObject* texture : active)
  {
    texture->Deactivate();
  }
  kept.Keep(source);
  std::copy(region, region + 4, this->UpdatedRegion);
  this->NumberOfPixelsRecast = region[2] >= region[0] && region[3] >= region[1]
    ? static_cast<vtkIdType>(region[2] - region[0] + 1) * (region[3] - region[1] + 1)
    : 0;
  this->LastRenderWasLocalized = localized;
  if (!kept.Draw(window))
  {
    this->LastErrorMessage = "the shader that draws the kept image does not compile on this OpenGL context";
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
namespace
{
template <typename Draw>
void WithSurfaceState(vtkOpenGLRenderWindow* window, Draw draw)
{
  vtkOpenGLState* state = window->GetState();
  vtkOpenGLState::ScopedglDepthMask depthMask(state);
  vtkOpenGLState::ScopedglDepthFunc depthFunc(state);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFunc(state);
  vtkOpenGLState::ScopedglEnableDisable blend(state, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthTest(state, GL_DEPTH_TEST);
  // Premultiplied colour over what is drawn; rays already stopped at opaque
  // geometry, so the depth written (the surface's) always wins.
  state->vtkglEnable(GL_BLEND);
  state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_ALWAYS);
  state->vtkglDepthMask(GL_TRUE);
  draw();
}
}

//------------------------------------------------------------------------------
void vtkVolumeCutOpenGLRayCaster::DrawSurfaceQuad(vtkOpenGLRenderWindow* window, vtkOpenGLQuadHelper* quad)
{
  WithSurfaceState(window, [quad]() { quad->Render(); });
}

//------------------------------------------------------------------------------
void vtkVolumeCutOpenGLRayCaster::DrawSurfaceQuad(vtkOpenGLRenderWindow* window, vtkOpenGLVertexArrayObject* quad)
{
  WithSurfaceState(window, [quad]() {
    quad->Bind();
    vtkOpenGLRenderUtilities::DrawFullScreenQuad();
    quad->Release();
  });
}

//------------------------------------------------------------------------------
std::string vtkVolumeCutOpenGLRayCaster::DefaultProgramCacheDirectory()
{
  return vtkVolumeCutProgramBuilder::DefaultCacheDirectory();
}

//------------------------------------------------------------------------------
void vtkVolumeCutOpenGLRayCaster::SetProgramBuildTimeLimit(double seconds)
{
  // Set again, the limit lets the GPU path try once more.
  this->Impl->Program.ClearTimeOut();
  if (this->ProgramStatus == ProgramTimedOut)
  {
    this->ProgramStatus = ProgramNone;
  }
  this->ProgramBuildTimeLimit = std::max(0.0, seconds);
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkVolumeCutOpenGLRayCaster::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfBricksUploaded: " << this->NumberOfBricksUploaded << " (total " << this->TotalNumberOfBricksUploaded
     << ")\n";
  os << indent << "TextureMemorySize: " << this->GetTextureMemorySize() << "\n";
  os << indent << "NormalizedTextures: " << this->NormalizedTextures << "\n";
  os << indent << "AnatomyTextureBytesPerVoxel: " << this->AnatomyTextureBytesPerVoxel << "\n";
  os << indent << "LabelTextureBytesPerVoxel: " << this->LabelTextureBytesPerVoxel << "\n";
  os << indent << "FractionTextureBytesPerVoxel: " << this->FractionTextureBytesPerVoxel << "\n";
  os << indent << "CutAtlasTextureBytesPerVoxel: " << this->CutAtlasTextureBytesPerVoxel << "\n";
  os << indent << "HardwareFiltering: " << this->HardwareFiltering << " (CT " << this->AnatomyHardwareFiltered << ", fractions "
     << this->FractionsHardwareFiltered << ")\n";
  os << indent << "MaximumFilterWeightError: " << this->MaximumFilterWeightError << " (measured " << this->FilterWeightError << ")\n";
  os << indent << "EmulatedFilterWeightBits: " << this->EmulatedFilterWeightBits << "\n";
  os << indent << "LocalizedUpdates: " << this->LocalizedUpdates << "\n";
  os << indent << "EmptySpaceSkipping: " << this->EmptySpaceSkipping << "\n";
  os << indent << "NumberOfPixelsRecast: " << this->NumberOfPixelsRecast << (this->LastRenderWasLocalized ? " (localized)" : "")
     << ", region " << this->UpdatedRegion[0] << " " << this->UpdatedRegion[1] << " " << this->UpdatedRegion[2] << " "
     << this->UpdatedRegion[3] << "\n";
  os << indent << "LastErrorMessage: " << this->LastErrorMessage << "\n";
  os << indent << "ProgramStatus: " << this->ProgramStatus << " (" << this->ProgramFeatures << ", " << this->ProgramSourceLength
     << " characters)\n";
  os << indent << "ProgramBuildTimeLimit: " << this->ProgramBuildTimeLimit << "\n";
  os << indent << "ProgramCacheDirectory: " << this->ProgramCacheDirectory << "\n";
  os << indent << "ProgramCache: " << this->ProgramCache << "\n";
  os << indent << "ExtraFragmentDeclarations: " << this->ExtraFragmentDeclarations << "\n";
  os << indent << "LastProgramBuildTime: " << this->LastProgramBuildTime << (this->LastProgramLoadedFromCache ? " (cached)" : "")
     << "\n";
  os << indent << "Driver: " << this->DriverDescription << " (parallel compile " << this->ParallelCompile << ", "
     << this->NumberOfProgramBinaryFormats << " binary formats)\n";
}
