// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutFilterProbe.h"

#include "vtkVolumeCutTextureUtilities.h"

#include <vtkNew.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLQuadHelper.h>
#include <vtkOpenGLRenderUtilities.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLShaderCache.h>
#include <vtkOpenGLState.h>
#include <vtkShaderProgram.h>
#include <vtkSmartPointer.h>
#include <vtkTextureObject.h>
#include <vtk_glad.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace
{
// Samples a 2-texel R16 texture (0 and 65535) with GL_LINEAR at a row of
// points between the texel centres: what the texture unit returns against
// the exact lerp tells how finely it weights texels.
const char* const FilterProbeFragmentShader = R"GLSL(//VTK::System::Dec
//VTK::Output::Dec
in vec2 texCoord;
uniform sampler3D probeTexture;
uniform float pointCount;
void main()
{
  // Pixel k (texCoord (k + 0.5) / pointCount) samples (k + 0.37) / pointCount:
  // points off any grid of 2^-n steps.
  float x = (floor(texCoord.x * pointCount) + 0.37) / pointCount;
  gl_FragData[0] = vec4(textureLod(probeTexture, vec3(0.5 * (x + 0.5), 0.5, 0.5), 0.0).r, 0.0, 0.0, 1.0);
}
)GLSL";
}

//------------------------------------------------------------------------------
void vtkVolumeCutFilterProbe::MeasureOnce(vtkOpenGLRenderWindow* window)
{
  if (!this->Measured)
  {
    this->FilterWeightError = Measure(window);
    this->Measured = true;
  }
}

//------------------------------------------------------------------------------
void vtkVolumeCutFilterProbe::Forget()
{
  this->FilterWeightError = -1.0;
  this->Measured = false;
}

//------------------------------------------------------------------------------
double vtkVolumeCutFilterProbe::Measure(vtkOpenGLRenderWindow* window)
{
  constexpr int points = 1021;
  const unsigned short texels[2] = { 0, 65535 };
  vtkSmartPointer<vtkTextureObject> probe =
    vtkVolumeCutTextureUtilities::Texture3D(window, 2, 1, 1, 1, VTK_UNSIGNED_SHORT, GL_R16, texels);
  if (!probe)
  {
    return -1.0;
  }
  vtkVolumeCutTextureUtilities::SetLinearFiltering(probe, true);
  auto target = vtkSmartPointer<vtkTextureObject>::New();
  target->SetContext(window);
  target->SetMinificationFilter(vtkTextureObject::Nearest);
  target->SetMagnificationFilter(vtkTextureObject::Nearest);
  double error = -1.0;
  if (vtkVolumeCutTextureUtilities::BytesPerVoxel(probe) == 2 && target->Allocate2D(points, 1, 1, VTK_FLOAT))
  {
    vtkNew<vtkOpenGLFramebufferObject> framebuffer;
    framebuffer->SetContext(window);
    vtkOpenGLState* state = window->GetState();
    state->PushFramebufferBindings();
    framebuffer->Bind();
    framebuffer->AddColorAttachment(0, target);
    framebuffer->ActivateDrawBuffers(1);
    framebuffer->ActivateReadBuffer(0);
    const char* description = nullptr;
    vtkOpenGLQuadHelper quad(window, vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(), FilterProbeFragmentShader, "");
    if (vtkOpenGLFramebufferObject::GetFrameBufferStatus(vtkOpenGLFramebufferObject::GetDrawMode(), description) && quad.Program &&
      quad.Program->GetCompiled())
    {
      std::vector<float> values(points, -1.f);
      {
        vtkOpenGLState::ScopedglViewport viewport(state);
        vtkOpenGLState::ScopedglEnableDisable scissorTest(state, GL_SCISSOR_TEST);
        vtkOpenGLState::ScopedglEnableDisable blend(state, GL_BLEND);
        vtkOpenGLState::ScopedglEnableDisable depthTest(state, GL_DEPTH_TEST);
        vtkOpenGLState::ScopedglColorMask colorMask(state);
        state->vtkglViewport(0, 0, points, 1);
        state->vtkglDisable(GL_SCISSOR_TEST);
        state->vtkglDisable(GL_BLEND);
        state->vtkglDisable(GL_DEPTH_TEST);
        state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        window->GetShaderCache()->ReadyShaderProgram(quad.Program);
        probe->Activate();
        quad.Program->SetUniformi("probeTexture", probe->GetTextureUnit());
        quad.Program->SetUniformf("pointCount", static_cast<float>(points));
        quad.Render();
        probe->Deactivate();
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, points, 1, GL_RED, GL_FLOAT, values.data());
      }
      error = 0.0;
      for (int k = 0; k < points && error >= 0.0; ++k)
      {
        const double x = (k + 0.37) / points;
        error = values[k] >= 0.f ? std::max(error, std::abs(values[k] - x)) : -1.0;
      }
    }
    quad.ReleaseGraphicsResources(window);
    framebuffer->ReleaseGraphicsResources(window);
    state->PopFramebufferBindings();
  }
  probe->ReleaseGraphicsResources(window);
  target->ReleaseGraphicsResources(window);
  return error;
}
