// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutVolumeMapper.h"

#include "vtkVolumeCutOpenGLRayCaster.h"
#include "vtkVolumeCutRayCaster.h"

#include <vtkCallbackCommand.h>
#include <vtkColorTransferFunction.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkMatrix3x3.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLCamera.h>
#include <vtkOpenGLQuadHelper.h>
#include <vtkOpenGLRenderUtilities.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLShaderCache.h>
#include <vtkOpenGLState.h>
#include <vtkPiecewiseFunction.h>
#include <vtkCallbackCommand.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkShaderProgram.h>
#include <vtkSmartPointer.h>
#include <vtkTextureObject.h>
#include <vtkTimerLog.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWeakPointer.h>
#include <vtk_glad.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutVolumeMapper);

namespace
{
// Draws the CPU reference's image: premultiplied colour and the surface depth.
const char* const ImageFragmentShader = R"GLSL(//VTK::System::Dec
//VTK::Output::Dec
in vec2 texCoord;
uniform sampler2D colorTexture;
uniform sampler2D depthTexture;
// The share of the image over the viewport (less than 1 where a reduced
// image's last block reaches past the viewport's edge).
uniform vec2 imageScale;
void main()
{
  vec2 position = texCoord * imageScale;
  vec4 color = texture(colorTexture, position);
  if (color.a <= 0.0)
  {
    discard;
  }
  gl_FragData[0] = color;
  gl_FragDepth = texture(depthTexture, position).r;
}
)GLSL";
}

//------------------------------------------------------------------------------
struct vtkVolumeCutVolumeMapper::Internals
{
  vtkNew<vtkVolumeCutRayCaster> RayCaster;
  vtkNew<vtkVolumeCutOpenGLRayCaster> OpenGLRayCaster;
  vtkImageData* AnatomyImage = nullptr;
  double AnatomyMatrix[16] = {};
  vtkPlaneCollection* Planes = nullptr;
  vtkColorTransferFunction* ColorFunction = nullptr;
  vtkPiecewiseFunction* OpacityFunction = nullptr;
  std::string FallbackReason;
  // What a reduced CPU frame cost: its work besides casting rays
  // (the opaque depth read back, the scene prepared, the image drawn at the
  // viewport's size), which does not shrink with the image, and its cost
  // per ray. The next interactive frame's resolution is chosen from it.
  // Not from a full frame's: its rays lie next to each other and share
  // the memory they read, while a reduced frame's each read their own and
  // cost up to twice as much (1.2 against 2.2 microseconds on the
  // patient-scale CT), so the first moving frame, sized from a full one,
  // took 60 to 70 ms of a 50 ms frame.
  struct FrameCost
  {
    double Fixed = 0.0;  // seconds
    double PerRay = 0.0; // seconds
    bool Measured = false;
  };
  // The last few reduced frames' (the latest at DraftCostNext - 1): a grid
  // is sized for the dearest of them. Another program taking the cores for
  // a frame or two (as on a shared machine) made one frame cheap and the
  // next, sized from it, take 60 to 80 ms; the resolution comes back a few
  // frames after the cores do.
  static constexpr int RecentDraftFrames = 3;
  FrameCost DraftCost[RecentDraftFrames];
  int DraftCostNext = 0;
  // The last full frame's: whether a full frame fits.
  FrameCost FullCost;
  // What the window's frame costs besides this mapper (clearing, other
  // props, compositing and swapping): an interactive frame leaves it its
  // share of the time the window allows.
  double RestOfFrame = 0.0;
  double WindowFrameStart = 0.0;
  double MapperTimeInFrame = 0.0;
  vtkWeakPointer<vtkRenderWindow> TimedWindow;
  unsigned long FrameStartTag = 0;
  unsigned long FrameEndTag = 0;

  void TimeFramesOf(vtkRenderWindow* window)
  {
    if (window == this->TimedWindow)
    {
      return;
    }
    this->StopTimingFrames();
    this->TimedWindow = window;
    this->RestOfFrame = 0.0;
    this->MapperTimeInFrame = -1.0;
    vtkNew<vtkCallbackCommand> start;
    start->SetClientData(this);
    start->SetCallback([](vtkObject*, unsigned long, void* clientData, void*) {
      Internals* self = static_cast<Internals*>(clientData);
      self->WindowFrameStart = vtkTimerLog::GetUniversalTime();
      self->MapperTimeInFrame = -1.0;
    });
    vtkNew<vtkCallbackCommand> end;
    end->SetClientData(this);
    end->SetCallback([](vtkObject*, unsigned long, void* clientData, void*) {
      Internals* self = static_cast<Internals*>(clientData);
      if (self->MapperTimeInFrame >= 0.0)
      {
        self->RestOfFrame = std::max(0.0, vtkTimerLog::GetUniversalTime() - self->WindowFrameStart - self->MapperTimeInFrame);
      }
    });
    this->FrameStartTag = window->AddObserver(vtkCommand::StartEvent, start);
    this->FrameEndTag = window->AddObserver(vtkCommand::EndEvent, end);
  }

  void StopTimingFrames()
  {
    if (this->TimedWindow)
    {
      this->TimedWindow->RemoveObserver(this->FrameStartTag);
      this->TimedWindow->RemoveObserver(this->FrameEndTag);
    }
    this->TimedWindow = nullptr;
  }
  int ReportedPath = 0;
  std::string ReportedReason;
  bool ReportedNoInput = false;
  // While the GPU program builds in parallel: a timer of the window's
  // interactor asks for frames until it is ready.
  // Weak: an interactor that goes first takes its observer with it.
  vtkWeakPointer<vtkRenderWindowInteractor> Interactor;
  int ProgramTimer = 0;
  vtkNew<vtkCallbackCommand> ProgramTimerCallback;
  unsigned long ProgramTimerObserver = 0;

  static void OnProgramTimer(vtkObject* caller, unsigned long, void* clientData, void* callData)
  {
    auto* self = static_cast<Internals*>(clientData);
    auto* interactor = vtkRenderWindowInteractor::SafeDownCast(caller);
    if (!interactor || !callData || *static_cast<int*>(callData) != self->ProgramTimer)
    {
      return;
    }
    self->ProgramTimer = 0;
    interactor->Render();
  }

  void AskForFrame(vtkRenderWindowInteractor* interactor)
  {
    if (!interactor)
    {
      return;
    }
    if (interactor != this->Interactor)
    {
      // Another interactor (or the last one gone): its timer is no longer ours.
      this->StopAsking();
      this->ProgramTimerCallback->SetClientData(this);
      this->ProgramTimerCallback->SetCallback(&Internals::OnProgramTimer);
      this->ProgramTimerObserver = interactor->AddObserver(vtkCommand::TimerEvent, this->ProgramTimerCallback);
      this->Interactor = interactor;
    }
    if (!this->ProgramTimer)
    {
      this->ProgramTimer = interactor->CreateOneShotTimer(100);
    }
  }

  void StopAsking()
  {
    if (this->Interactor)
    {
      if (this->ProgramTimer)
      {
        this->Interactor->DestroyTimer(this->ProgramTimer);
      }
      this->Interactor->RemoveObserver(this->ProgramTimerObserver);
    }
    this->Interactor = nullptr;
    this->ProgramTimer = 0;
  }
  vtkOpenGLRenderWindow* Context = nullptr;
  vtkSmartPointer<vtkTextureObject> Color;
  vtkSmartPointer<vtkTextureObject> Depth;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;

  void Release(vtkWindow* window)
  {
    if (this->Color)
    {
      this->Color->ReleaseGraphicsResources(window);
      this->Depth->ReleaseGraphicsResources(window);
    }
    this->Color = this->Depth = nullptr;
    if (this->Quad)
    {
      this->Quad->ReleaseGraphicsResources(window);
      this->Quad.reset();
    }
    this->OpenGLRayCaster->ReleaseGraphicsResources(window);
    this->Context = nullptr;
  }
};

//------------------------------------------------------------------------------
vtkVolumeCutVolumeMapper::vtkVolumeCutVolumeMapper()
  : Impl(new Internals)
{
  this->BlendMode = vtkVolumeMapper::ISOSURFACE_BLEND;
}

//------------------------------------------------------------------------------
vtkVolumeCutVolumeMapper::~vtkVolumeCutVolumeMapper()
{
  this->Impl->StopTimingFrames();
  this->Impl->StopAsking();
  if (this->Impl->Context)
  {
    this->Impl->Release(this->Impl->Context);
  }
}

//------------------------------------------------------------------------------
int vtkVolumeCutVolumeMapper::FillInputPortInformation(int vtkNotUsed(port), vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
vtkVolumeCutRayCaster* vtkVolumeCutVolumeMapper::GetRayCaster()
{
  return this->Impl->RayCaster;
}

//------------------------------------------------------------------------------
vtkVolumeCutOpenGLRayCaster* vtkVolumeCutVolumeMapper::GetOpenGLRayCaster()
{
  return this->Impl->OpenGLRayCaster;
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutVolumeMapper::GetLastRenderPathAsString() const
{
  switch (this->LastRenderPath)
  {
    case GPUPath:
      return "GPU";
    case CPUPath:
      return "CPU";
    default:
      return "none";
  }
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutVolumeMapper::GetGPUFallbackReason() const
{
  return this->Impl->FallbackReason.c_str();
}

//------------------------------------------------------------------------------
void vtkVolumeCutVolumeMapper::SetProgramBuildTimeLimit(double seconds)
{
  this->Impl->OpenGLRayCaster->SetProgramBuildTimeLimit(seconds);
  this->Modified();
}

//------------------------------------------------------------------------------
double vtkVolumeCutVolumeMapper::GetProgramBuildTimeLimit()
{
  return this->Impl->OpenGLRayCaster->GetProgramBuildTimeLimit();
}

//------------------------------------------------------------------------------
void vtkVolumeCutVolumeMapper::SetProgramCacheDirectory(const char* directory)
{
  this->Impl->OpenGLRayCaster->SetProgramCacheDirectory(directory);
  this->Modified();
}

//------------------------------------------------------------------------------
const char* vtkVolumeCutVolumeMapper::GetProgramCacheDirectory()
{
  return this->Impl->OpenGLRayCaster->GetProgramCacheDirectory();
}

//------------------------------------------------------------------------------
double vtkVolumeCutVolumeMapper::GetLastProgramBuildTime()
{
  return this->Impl->OpenGLRayCaster->GetLastProgramBuildTime();
}

//------------------------------------------------------------------------------
void vtkVolumeCutVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Impl->Release(window);
}

//------------------------------------------------------------------------------
void vtkVolumeCutVolumeMapper::Render(vtkRenderer* renderer, vtkVolume* volume)
{
  Internals& impl = *this->Impl;
  const double start = vtkTimerLog::GetUniversalTime();
  this->LastRenderPath = 0;
  vtkOpenGLRenderWindow* window = renderer ? vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow()) : nullptr;
  if (!window || !volume)
  {
    vtkErrorMacro("Render: needs an OpenGL render window and a volume");
    return;
  }
  if (!window->GetState() || !window->IsCurrent())
  {
    vtkErrorMacro("Render: the OpenGL context is not current (lost?); nothing drawn");
    return;
  }
  if (impl.Context && impl.Context != window)
  {
    impl.Release(impl.Context);
  }
  impl.Context = window;

  vtkImageData* image = vtkImageData::SafeDownCast(this->GetInput());
  if (!image)
  {
    if (!impl.ReportedNoInput)
    {
      vtkErrorMacro("Render: no anatomy image as input; nothing drawn");
      impl.ReportedNoInput = true;
    }
    return;
  }
  impl.ReportedNoInput = false;
  vtkVolumeCutRayCaster* caster = impl.RayCaster;

  // Only real changes reach the caster, so that unchanged frames after a cut
  // stay localized updates on the CPU path.
  vtkNew<vtkMatrix4x4> ijkToWorld;
  vtkMatrix4x4::Multiply4x4(volume->GetMatrix(), image->GetIndexToPhysicalMatrix(), ijkToWorld);
  if (image != impl.AnatomyImage || !std::equal(&ijkToWorld->Element[0][0], &ijkToWorld->Element[0][0] + 16, impl.AnatomyMatrix))
  {
    caster->SetAnatomy(image, ijkToWorld);
    impl.AnatomyImage = image;
    std::copy(&ijkToWorld->Element[0][0], &ijkToWorld->Element[0][0] + 16, impl.AnatomyMatrix);
  }
  if (this->ClippingPlanes != impl.Planes)
  {
    caster->SetClippingPlanes(this->ClippingPlanes);
    impl.Planes = this->ClippingPlanes;
  }
  caster->SetBlendMode(
    this->BlendMode == vtkVolumeMapper::COMPOSITE_BLEND ? vtkVolumeCutRayCaster::CompositeBlend : vtkVolumeCutRayCaster::IsoSurfaceBlend);
  if (this->BlendMode == vtkVolumeMapper::COMPOSITE_BLEND)
  {
    vtkVolumeProperty* property = volume->GetProperty();
    vtkColorTransferFunction* color = property->GetRGBTransferFunction(0);
    vtkPiecewiseFunction* opacity = property->GetScalarOpacity(0);
    if (color != impl.ColorFunction || opacity != impl.OpacityFunction)
    {
      caster->SetTransferFunctions(color, opacity);
      impl.ColorFunction = color;
      impl.OpacityFunction = opacity;
    }
    caster->SetScalarOpacityUnitDistance(property->GetScalarOpacityUnitDistance(0));
  }

  // The camera of this eye (stereo renders each eye with its own matrices).
  vtkMatrix4x4* wcvc = nullptr;
  vtkMatrix3x3* normals = nullptr;
  vtkMatrix4x4* vcdc = nullptr;
  vtkMatrix4x4* wcdc = nullptr;
  vtkOpenGLCamera::SafeDownCast(renderer->GetActiveCamera())->GetKeyMatrices(renderer, wcvc, normals, vcdc, wcdc);
  vtkNew<vtkMatrix4x4> worldToNDC;
  vtkMatrix4x4::Transpose(wcdc, worldToNDC); // GetKeyMatrices gives OpenGL's column order
  int width = 0;
  int height = 0;
  int x0 = 0;
  int y0 = 0;
  renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  if (width < 1 || height < 1)
  {
    return;
  }
  std::vector<float> opaqueDepth(static_cast<size_t>(width) * height, 1.f);
  window->GetZbufferData(x0, y0, x0 + width - 1, y0 + height - 1, opaqueDepth.data());

  int path = CPUPath;
  const char* rendererName = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string glRenderer = rendererName ? rendererName : "";
  // A software rasterizer runs the shader on the CPU, one fragment at a time:
  // the multithreaded CPU reference is faster there.
  const bool softwareRenderer = glRenderer.find("llvmpipe") != std::string::npos || glRenderer.find("softpipe") != std::string::npos ||
    glRenderer.find("SwiftShader") != std::string::npos || glRenderer.find("swrast") != std::string::npos;
  if (this->RequestedRenderPath == AutomaticPath && softwareRenderer)
  {
    impl.FallbackReason = "the OpenGL renderer (" + glRenderer + ") is a software rasterizer, where the CPU reference is faster";
  }
  else if (this->RequestedRenderPath != CPUPath)
  {
    vtkVolumeCutOpenGLRayCaster* gpu = impl.OpenGLRayCaster;
    if (gpu->Render(window, caster, worldToNDC, x0, y0, width, height, opaqueDepth.data()))
    {
      path = GPUPath;
      impl.FallbackReason.clear();
    }
    else
    {
      // Whatever stops the GPU (a program still building, rejected or too
      // slow to build, a volume beyond the texture limit), the CPU draws:
      // the view never freezes.
      impl.FallbackReason = gpu->GetLastErrorMessage();
    }
    if (gpu->GetProgramStatus() == vtkVolumeCutOpenGLRayCaster::ProgramPending)
    {
      impl.AskForFrame(renderer->GetRenderWindow()->GetInteractor());
    }
  }
  int sampleDistance = 1;
  if (path == CPUPath)
  {
    sampleDistance = this->ChooseImageSampleDistance(renderer, width, height);
    if (!this->RenderOnCPU(renderer, worldToNDC, width, height, opaqueDepth, sampleDistance))
    {
      return;
    }
  }
  const bool transient = path == CPUPath && impl.OpenGLRayCaster->GetProgramStatus() == vtkVolumeCutOpenGLRayCaster::ProgramPending &&
    this->RequestedRenderPath != CPUPath;
  if (!transient && (path != impl.ReportedPath || (path == CPUPath && impl.FallbackReason != impl.ReportedReason)))
  {
    // Once per change, so that the log says which implementation draws and
    // why (a program still building is no reason to warn).
    if (path == CPUPath && this->RequestedRenderPath != CPUPath)
    {
      vtkWarningMacro("Rendering cuts on the CPU" << (this->RequestedRenderPath == GPUPath ? " although the GPU path was requested" : "")
                                                  << ": " << impl.FallbackReason);
    }
    impl.ReportedPath = path;
    impl.ReportedReason = path == CPUPath ? impl.FallbackReason : std::string();
  }
  this->LastRenderPath = path;
  this->LastImageSampleDistance = sampleDistance;
  this->LastFrameTime = vtkTimerLog::GetUniversalTime() - start;
  impl.MapperTimeInFrame = this->LastFrameTime;
  if (path == CPUPath && caster->GetNumberOfRaysCast() > 0 && !caster->GetLastRenderWasLocalized())
  {
    Internals::FrameCost& cost = sampleDistance > 1 ? impl.DraftCost[impl.DraftCostNext] : impl.FullCost;
    if (sampleDistance > 1)
    {
      impl.DraftCostNext = (impl.DraftCostNext + 1) % Internals::RecentDraftFrames;
    }
    const double casting = std::min(caster->GetLastRayCastingTime(), this->LastFrameTime);
    cost.PerRay = casting / static_cast<double>(caster->GetNumberOfRaysCast());
    cost.Fixed = this->LastFrameTime - casting;
    cost.Measured = true;
  }
}

//------------------------------------------------------------------------------
double vtkVolumeCutVolumeMapper::GetRestOfFrameTime() const
{
  return this->Impl->RestOfFrame;
}

//------------------------------------------------------------------------------
int vtkVolumeCutVolumeMapper::ChooseImageSampleDistance(vtkRenderer* renderer, int width, int height)
{
  vtkRenderWindow* window = renderer->GetRenderWindow();
  this->Impl->TimeFramesOf(window);
  const double rate = window->GetDesiredUpdateRate();
  if (this->MaximumImageSampleDistance <= 1 || rate < this->InteractiveUpdateRate)
  {
    return 1;
  }
  const Internals::FrameCost& full = this->Impl->FullCost;
  const Internals::FrameCost* drafts = this->Impl->DraftCost;
  const bool draftMeasured = std::any_of(
    drafts, drafts + Internals::RecentDraftFrames, [](const Internals::FrameCost& cost) { return cost.Measured; });
  if (!full.Measured && !draftMeasured)
  {
    // No frame measured yet: the coarsest, so that the first motion responds.
    return this->MaximumImageSampleDistance;
  }
  // The rest of the window's frame takes its time first; the mapper keeps
  // at least a fifth of the frame, so that a slow window does not leave it
  // nothing but the coarsest image. A fifth of the time is spared: as the
  // view turns, the cost of a grid changes from one frame to the next by up
  // to 15-20 % (the head CT orbited 180 degrees a degree a frame, processor
  // time per frame), and sparing a tenth let one frame in twenty run over.
  const double allowed = 0.8 * std::max(0.2 / rate, 1.0 / rate - this->Impl->RestOfFrame);
  if (full.Measured && full.Fixed + full.PerRay * width * height <= allowed)
  {
    return 1;
  }
  if (!draftMeasured)
  {
    // No reduced frame measured yet: the coarsest; the frames after it are
    // sized from its cost, each finer than the last until they fill the
    // time (a sparser grid's rays cost more each: the estimate errs
    // towards the coarser).
    return this->MaximumImageSampleDistance;
  }
  // The finest grid whose frame fits.
  for (int distance = 2; distance < this->MaximumImageSampleDistance; ++distance)
  {
    const double rays = static_cast<double>((width + distance - 1) / distance) * ((height + distance - 1) / distance);
    double predicted = 0.0;
    for (int n = 0; n < Internals::RecentDraftFrames; ++n)
    {
      if (drafts[n].Measured)
      {
        predicted = std::max(predicted, drafts[n].Fixed + drafts[n].PerRay * rays);
      }
    }
    if (predicted <= allowed)
    {
      return distance;
    }
  }
  return this->MaximumImageSampleDistance;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutVolumeMapper::RenderOnCPU(
  vtkRenderer* vtkNotUsed(renderer), vtkMatrix4x4* worldToNDC, int width, int height, const std::vector<float>& opaqueDepth, int sampleDistance)
{
  vtkVolumeCutRayCaster* caster = this->Impl->RayCaster;
  if (sampleDistance <= 1)
  {
    return caster->Render(worldToNDC, width, height, opaqueDepth.data()) && this->DrawCPUImage(width, height, false, 1.0, 1.0);
  }
  // One ray at the centre of each block of pixels; the opaque geometry's
  // depth is read there too (NDC is independent of the image's size).
  const int reducedWidth = (width + sampleDistance - 1) / sampleDistance;
  const int reducedHeight = (height + sampleDistance - 1) / sampleDistance;
  std::vector<float> reducedDepth(static_cast<size_t>(reducedWidth) * reducedHeight);
  for (int y = 0; y < reducedHeight; ++y)
  {
    const int sourceY = std::min(height - 1, y * sampleDistance + sampleDistance / 2);
    for (int x = 0; x < reducedWidth; ++x)
    {
      const int sourceX = std::min(width - 1, x * sampleDistance + sampleDistance / 2);
      reducedDepth[static_cast<size_t>(y) * reducedWidth + x] = opaqueDepth[static_cast<size_t>(sourceY) * width + sourceX];
    }
  }
  // The reduced grid covers a little more than the viewport where the size
  // is not a multiple of the distance: scale NDC so that its pixels stay square.
  vtkNew<vtkMatrix4x4> toReduced;
  toReduced->SetElement(0, 0, static_cast<double>(width) / (reducedWidth * sampleDistance));
  toReduced->SetElement(1, 1, static_cast<double>(height) / (reducedHeight * sampleDistance));
  toReduced->SetElement(0, 3, toReduced->GetElement(0, 0) - 1.0);
  toReduced->SetElement(1, 3, toReduced->GetElement(1, 1) - 1.0);
  vtkNew<vtkMatrix4x4> reducedWorldToNDC;
  vtkMatrix4x4::Multiply4x4(toReduced, worldToNDC, reducedWorldToNDC);
  // Ambient occlusion costs more than the rest of a ray on real data (14
  // more lookups a surface point) and reads only in a still image: moving
  // frames go without it, as VTK's mappers lower quality while interacting.
  caster->SetDraftQuality(true);
  const bool cast = caster->Render(reducedWorldToNDC, reducedWidth, reducedHeight, reducedDepth.data());
  caster->SetDraftQuality(false);
  return cast &&
    this->DrawCPUImage(reducedWidth, reducedHeight, true, toReduced->GetElement(0, 0), toReduced->GetElement(1, 1));
}

//------------------------------------------------------------------------------
bool vtkVolumeCutVolumeMapper::DrawCPUImage(int width, int height, bool magnified, double scaleX, double scaleY)
{
  Internals& impl = *this->Impl;
  vtkOpenGLRenderWindow* window = impl.Context;
  vtkVolumeCutRayCaster* caster = impl.RayCaster;
  auto makeTexture = [window](vtkSmartPointer<vtkTextureObject>& texture, int components, const float* data, int w, int h) {
    if (!texture)
    {
      texture = vtkSmartPointer<vtkTextureObject>::New();
      texture->SetContext(window);
      texture->SetWrapS(vtkTextureObject::ClampToEdge);
      texture->SetWrapT(vtkTextureObject::ClampToEdge);
      texture->SetMinificationFilter(vtkTextureObject::Nearest);
      texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    }
    return texture->Create2DFromRaw(w, h, components, VTK_FLOAT, const_cast<float*>(data));
  };
  int region[4];
  caster->GetUpdatedRegion(region);
  const bool sameSize = impl.Color && static_cast<int>(impl.Color->GetWidth()) == width &&
    static_cast<int>(impl.Color->GetHeight()) == height && caster->GetLastRenderWasLocalized();
  if (sameSize)
  {
    // A localized update: only the changed rectangle travels to the GPU.
    if (region[2] >= region[0] && region[3] >= region[1])
    {
      glPixelStorei(GL_UNPACK_ROW_LENGTH, width);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      const size_t offset = static_cast<size_t>(region[1]) * width + region[0];
      impl.Color->Bind();
      glTexSubImage2D(GL_TEXTURE_2D, 0, region[0], region[1], region[2] - region[0] + 1, region[3] - region[1] + 1, GL_RGBA, GL_FLOAT,
        caster->GetColorBuffer() + 4 * offset);
      impl.Depth->Bind();
      glTexSubImage2D(GL_TEXTURE_2D, 0, region[0], region[1], region[2] - region[0] + 1, region[3] - region[1] + 1, GL_RED, GL_FLOAT,
        caster->GetDepthBuffer() + offset);
      glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    }
  }
  else if (!makeTexture(impl.Color, 4, caster->GetColorBuffer(), width, height) ||
    !makeTexture(impl.Depth, 1, caster->GetDepthBuffer(), width, height))
  {
    vtkErrorMacro("Render: no GPU memory for a " << width << " x " << height << " image");
    return false;
  }
  if (!impl.Quad)
  {
    impl.Quad.reset(
      new vtkOpenGLQuadHelper(window, vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(), ImageFragmentShader, ""));
  }
  if (!impl.Quad->Program || !impl.Quad->Program->GetCompiled())
  {
    vtkErrorMacro("Render: the image shader does not compile on this OpenGL context");
    return false;
  }
  // A magnified image is filtered so that its blocks do not flicker while
  // the camera moves; its depth stays that of one ray.
  impl.Color->SetMagnificationFilter(magnified ? vtkTextureObject::Linear : vtkTextureObject::Nearest);
  window->GetShaderCache()->ReadyShaderProgram(impl.Quad->Program);
  impl.Color->Activate();
  impl.Depth->Activate();
  impl.Quad->Program->SetUniformi("colorTexture", impl.Color->GetTextureUnit());
  impl.Quad->Program->SetUniformi("depthTexture", impl.Depth->GetTextureUnit());
  const float imageScale[2] = { static_cast<float>(scaleX), static_cast<float>(scaleY) };
  impl.Quad->Program->SetUniform2f("imageScale", imageScale);
  vtkVolumeCutOpenGLRayCaster::DrawSurfaceQuad(window, impl.Quad.get());
  impl.Color->Deactivate();
  impl.Depth->Deactivate();
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "RequestedRenderPath: " << this->RequestedRenderPath << "\n";
  os << indent << "LastRenderPath: " << this->GetLastRenderPathAsString() << "\n";
  os << indent << "GPUFallbackReason: " << this->Impl->FallbackReason << "\n";
  os << indent << "OpenGLRayCaster:\n";
  this->Impl->OpenGLRayCaster->PrintSelf(os, indent.GetNextIndent());
  os << indent << "LastFrameTime: " << this->LastFrameTime << "\n";
  os << indent << "InteractiveUpdateRate: " << this->InteractiveUpdateRate << "\n";
  os << indent << "MaximumImageSampleDistance: " << this->MaximumImageSampleDistance << "\n";
  os << indent << "LastImageSampleDistance: " << this->LastImageSampleDistance << "\n";
  os << indent << "RayCaster:\n";
  this->Impl->RayCaster->PrintSelf(os, indent.GetNextIndent());
}
