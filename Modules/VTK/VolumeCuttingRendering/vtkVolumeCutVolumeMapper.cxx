// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutVolumeMapper.h"

#include "vtkVolumeCutOpenGLRayCaster.h"
#include "vtkVolumeCutRayCaster.h"

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
#include <vtkRenderer.h>
#include <vtkShaderProgram.h>
#include <vtkSmartPointer.h>
#include <vtkTextureObject.h>
#include <vtkTimerLog.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtk_glad.h>

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
void main()
{
  vec4 color = texture(colorTexture, texCoord);
  if (color.a <= 0.0)
  {
    discard;
  }
  gl_FragData[0] = color;
  gl_FragDepth = texture(depthTexture, texCoord).r;
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
  int ReportedPath = 0;
  bool ReportedNoInput = false;
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
    if (impl.OpenGLRayCaster->Render(window, caster, worldToNDC, x0, y0, width, height, opaqueDepth.data()))
    {
      path = GPUPath;
      impl.FallbackReason.clear();
    }
    else
    {
      impl.FallbackReason = impl.OpenGLRayCaster->GetLastErrorMessage();
      if (this->RequestedRenderPath == GPUPath)
      {
        vtkErrorMacro("Render: the GPU path was requested but cannot run: " << impl.FallbackReason);
        return;
      }
    }
  }
  if (path == CPUPath)
  {
    if (!caster->Render(worldToNDC, width, height, opaqueDepth.data()) || !this->DrawCPUImage(renderer, x0, y0, width, height))
    {
      return;
    }
  }
  if (path != impl.ReportedPath)
  {
    // Once per change, so that the log says which implementation draws.
    if (path == CPUPath && this->RequestedRenderPath == AutomaticPath)
    {
      vtkWarningMacro("Rendering cuts on the CPU: " << impl.FallbackReason);
    }
    impl.ReportedPath = path;
  }
  this->LastRenderPath = path;
  this->LastFrameTime = vtkTimerLog::GetUniversalTime() - start;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutVolumeMapper::DrawCPUImage(vtkRenderer* vtkNotUsed(renderer), int vtkNotUsed(x0), int vtkNotUsed(y0), int width, int height)
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
  window->GetShaderCache()->ReadyShaderProgram(impl.Quad->Program);
  impl.Color->Activate();
  impl.Depth->Activate();
  impl.Quad->Program->SetUniformi("colorTexture", impl.Color->GetTextureUnit());
  impl.Quad->Program->SetUniformi("depthTexture", impl.Depth->GetTextureUnit());
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
  os << indent << "LastFrameTime: " << this->LastFrameTime << "\n";
  os << indent << "RayCaster:\n";
  this->Impl->RayCaster->PrintSelf(os, indent.GetNextIndent());
}
