// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutKeptImage.h"

#include "vtkVolumeCutLocalizedUpdate.h"
#include "vtkVolumeCutOpenGLRayCaster.h"
#include "vtkVolumeCutTextureUtilities.h"

#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLQuadHelper.h>
#include <vtkOpenGLRenderUtilities.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLShaderCache.h>
#include <vtkOpenGLState.h>
#include <vtkOpenGLVertexArrayObject.h>
#include <vtkShaderProgram.h>
#include <vtkTextureObject.h>
#include <vtk_glad.h>

#include <algorithm>
#include <cstdint>

namespace
{
// Draws the kept image into the window: the ray caster's colour and depth
// as it wrote them, so that the window gets what a direct cast would give.
const char* const KeptImageFragmentShader = R"GLSL(//VTK::System::Dec
//VTK::Output::Dec
in vec2 texCoord;
uniform sampler2D colorTexture;
uniform sampler2D depthTexture;
void main()
{
  // The pixel the ray caster computes from the same texCoord.
  ivec2 pixel = ivec2(texCoord * vec2(textureSize(colorTexture, 0)));
  vec4 color = texelFetch(colorTexture, pixel, 0);
  if (color.a <= 0.0)
  {
    discard; // the ray caster discards where nothing is seen
  }
  gl_FragData[0] = color;
  gl_FragDepth = texelFetch(depthTexture, pixel, 0).r;
}
)GLSL";
}

//------------------------------------------------------------------------------
vtkVolumeCutKeptImage::vtkVolumeCutKeptImage() = default;

//------------------------------------------------------------------------------
vtkVolumeCutKeptImage::~vtkVolumeCutKeptImage() = default;

//------------------------------------------------------------------------------
bool vtkVolumeCutKeptImage::CastFrom(const Source& source, int width, int height) const
{
  const Source& kept = this->CastSource;
  return this->Valid && this->Width == width && this->Height == height &&
    std::equal(source.WorldToNDC, source.WorldToNDC + 16, kept.WorldToNDC) && kept.SceneVersion == source.SceneVersion &&
    kept.AnatomyVersion == source.AnatomyVersion && kept.LabelVersion == source.LabelVersion && kept.ProgramKey == source.ProgramKey &&
    kept.EmptySpaceSkipping == source.EmptySpaceSkipping && kept.Fields == source.Fields &&
    kept.OpaqueDepthVersion == source.OpaqueDepthVersion;
}

//------------------------------------------------------------------------------
void vtkVolumeCutKeptImage::GetModifiedRegion(const double worldToNDC[16], int width, int height, double reach, int region[4]) const
{
  region[0] = width;
  region[1] = height;
  region[2] = region[3] = -1;
  std::vector<uint8_t> mask(static_cast<size_t>(width) * height, 0);
  for (size_t n = 0; n < this->CastSource.Fields.size(); ++n)
  {
    vtkVolumeCutLocalizedUpdate::MarkModifiedBricks(
      this->CastSource.Fields[n], this->CastSource.Stamps[n], reach, worldToNDC, width, height, mask, region);
  }
}

//------------------------------------------------------------------------------
bool vtkVolumeCutKeptImage::Reserve(vtkOpenGLRenderWindow* window, int width, int height)
{
  if (this->Framebuffer && this->Width == width && this->Height == height)
  {
    return true;
  }
  return this->Allocate(window, width, height);
}

//------------------------------------------------------------------------------
bool vtkVolumeCutKeptImage::Allocate(vtkOpenGLRenderWindow* window, int width, int height)
{
  vtkVolumeCutTextureUtilities::Release(this->Color, window);
  vtkVolumeCutTextureUtilities::Release(this->Depth, window);
  if (this->Framebuffer)
  {
    this->Framebuffer->ReleaseGraphicsResources(window);
  }
  this->Valid = false;
  this->Width = this->Height = 0;
  this->Framebuffer = nullptr;
  this->Color = vtkSmartPointer<vtkTextureObject>::New();
  this->Color->SetContext(window);
  this->Depth = vtkSmartPointer<vtkTextureObject>::New();
  this->Depth->SetContext(window);
  for (vtkTextureObject* texture : { this->Color.GetPointer(), this->Depth.GetPointer() })
  {
    texture->SetWrapS(vtkTextureObject::ClampToEdge);
    texture->SetWrapT(vtkTextureObject::ClampToEdge);
    texture->SetMinificationFilter(vtkTextureObject::Nearest);
    texture->SetMagnificationFilter(vtkTextureObject::Nearest);
  }
  if (!this->Color->Allocate2D(width, height, 4, VTK_FLOAT) || !this->Depth->AllocateDepth(width, height, vtkTextureObject::Float32))
  {
    this->Color = this->Depth = nullptr;
    return false;
  }
  auto framebuffer = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
  framebuffer->SetContext(window);
  vtkOpenGLState* state = window->GetState();
  state->PushFramebufferBindings();
  framebuffer->Bind();
  framebuffer->AddColorAttachment(0, this->Color);
  framebuffer->AddDepthAttachment(this->Depth);
  framebuffer->ActivateDrawBuffers(1);
  const char* description = nullptr;
  const bool complete = vtkOpenGLFramebufferObject::GetFrameBufferStatus(vtkOpenGLFramebufferObject::GetDrawMode(), description);
  state->PopFramebufferBindings();
  if (!complete)
  {
    framebuffer->ReleaseGraphicsResources(window);
    this->Color = this->Depth = nullptr;
    return false;
  }
  this->Framebuffer = framebuffer;
  this->Width = width;
  this->Height = height;
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutKeptImage::Cast(vtkOpenGLRenderWindow* window, const int region[4], vtkOpenGLVertexArrayObject* quad)
{
  vtkOpenGLState* state = window->GetState();
  state->PushFramebufferBindings();
  this->Framebuffer->Bind();
  this->Framebuffer->ActivateDrawBuffers(1);
  {
    vtkOpenGLState::ScopedglViewport viewport(state);
    vtkOpenGLState::ScopedglScissor scissor(state);
    vtkOpenGLState::ScopedglEnableDisable scissorTest(state, GL_SCISSOR_TEST);
    vtkOpenGLState::ScopedglEnableDisable blend(state, GL_BLEND);
    vtkOpenGLState::ScopedglEnableDisable depthTest(state, GL_DEPTH_TEST);
    vtkOpenGLState::ScopedglDepthMask depthMask(state);
    vtkOpenGLState::ScopedglDepthFunc depthFunc(state);
    vtkOpenGLState::ScopedglClearColor clearColor(state);
    vtkOpenGLState::ScopedglColorMask colorMask(state);
    state->vtkglViewport(0, 0, this->Width, this->Height);
    state->vtkglEnable(GL_SCISSOR_TEST);
    state->vtkglScissor(region[0], region[1], region[2] - region[0] + 1, region[3] - region[1] + 1);
    state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    state->vtkglDepthMask(GL_TRUE);
    // Where the ray caster discards (nothing seen), the cleared pixel says so.
    state->vtkglClearColor(0.f, 0.f, 0.f, 0.f);
    state->vtkglClearDepth(1.0);
    state->vtkglClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    // The fragments as written, not blended: the window blends them when drawn.
    state->vtkglDisable(GL_BLEND);
    state->vtkglEnable(GL_DEPTH_TEST);
    state->vtkglDepthFunc(GL_ALWAYS);
    quad->Bind();
    vtkOpenGLRenderUtilities::DrawFullScreenQuad();
    quad->Release();
  }
  state->PopFramebufferBindings();
}

//------------------------------------------------------------------------------
void vtkVolumeCutKeptImage::Keep(const Source& source)
{
  this->Valid = true;
  this->CastSource = source;
}

//------------------------------------------------------------------------------
bool vtkVolumeCutKeptImage::Draw(vtkOpenGLRenderWindow* window)
{
  if (!this->Quad)
  {
    this->Quad.reset(new vtkOpenGLQuadHelper(
      window, vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(), KeptImageFragmentShader, ""));
  }
  if (!this->Quad->Program || !this->Quad->Program->GetCompiled())
  {
    return false;
  }
  window->GetShaderCache()->ReadyShaderProgram(this->Quad->Program);
  this->Color->Activate();
  this->Depth->Activate();
  this->Quad->Program->SetUniformi("colorTexture", this->Color->GetTextureUnit());
  this->Quad->Program->SetUniformi("depthTexture", this->Depth->GetTextureUnit());
  vtkVolumeCutOpenGLRayCaster::DrawSurfaceQuad(window, this->Quad.get());
  this->Color->Deactivate();
  this->Depth->Deactivate();
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumeCutKeptImage::Release(vtkWindow* window)
{
  vtkVolumeCutTextureUtilities::Release(this->Color, window);
  vtkVolumeCutTextureUtilities::Release(this->Depth, window);
  if (this->Framebuffer)
  {
    this->Framebuffer->ReleaseGraphicsResources(window);
  }
  if (this->Quad)
  {
    this->Quad->ReleaseGraphicsResources(window);
  }
  this->Framebuffer = nullptr;
  this->Color = this->Depth = nullptr;
  this->Quad.reset();
  this->Valid = false;
  this->Width = this->Height = 0;
  this->CastSource = Source();
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutKeptImage::GetMemorySize() const
{
  return vtkVolumeCutTextureUtilities::MemorySize(this->Color) + vtkVolumeCutTextureUtilities::MemorySize(this->Depth);
}
