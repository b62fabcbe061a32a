// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutOpenGLRayCaster.h"

#include "vtkVolumeCutField.h"
#include "vtkVolumeCutLocalizedUpdate.h"
#include "vtkVolumeCutProgramBuilder.h"
#include "vtkVolumeCutRayCaster.h"
#include "vtkVolumeCutShaderComposer.h"

#include <vtkAbstractArray.h>
#include <vtkIdList.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLQuadHelper.h>
#include <vtkOpenGLRenderUtilities.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLShaderCache.h>
#include <vtkOpenGLState.h>
#include <vtkOpenGLVertexArrayObject.h>
#include <vtkShaderProgram.h>
#include <vtkSmartPointer.h>
#include <vtkTextureObject.h>
#include <vtkTimerLog.h>
#include <vtk_glad.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkVolumeCutOpenGLRayCaster);

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

// A cut field's distances (short quanta) travel in R16 as value + this; the
// shader subtracts it (glsl/vtkVolumeCutCutFieldFS.glsl).
constexpr int CutAtlasOffset = 32768;

// Whether the CT loses nothing as a 16-bit unsigned normalized texture: each
// value v is minimum + k (float arithmetic, as the shader adds them) for an
// integer k in 0..65535. If so, texels holds each k and minimum is set.
bool ToUnorm16(const float* values, size_t count, float& minimum, std::vector<unsigned short>& texels)
{
  if (count == 0)
  {
    return false;
  }
  // NaNs are skipped here and refused below.
  float low = std::numeric_limits<float>::infinity();
  float high = -std::numeric_limits<float>::infinity();
  for (size_t n = 0; n < count; ++n)
  {
    low = std::min(low, values[n]);
    high = std::max(high, values[n]);
  }
  if (!(static_cast<double>(high) - static_cast<double>(low) <= 65535.0))
  {
    return false;
  }
  texels.resize(count);
  for (size_t n = 0; n < count; ++n)
  {
    const double offset = static_cast<double>(values[n]) - static_cast<double>(low);
    if (!(offset >= 0.0 && offset <= 65535.0))
    {
      return false;
    }
    const int k = static_cast<int>(offset + 0.5);
    if (low + static_cast<float>(k) != values[n])
    {
      return false;
    }
    texels[n] = static_cast<unsigned short>(k);
  }
  minimum = low;
  return true;
}

struct CutTextures
{
  vtkVolumeCutField* Field = nullptr;
  vtkSmartPointer<vtkTextureObject> Page;
  vtkSmartPointer<vtkTextureObject> Atlas;
  int SlotsPerAxis = 0;
  int UsedSlots = 0;
  std::vector<int> SlotOfBrick;
  vtkTypeUInt64 Stamp = 0;
  int Dimensions[3] = { 0, 0, 0 };
  // The atlas as asked (NormalizedTextures) and as made: R16 holding
  // distance + 32768, or R32F where the driver offers no R16.
  bool Unorm16Requested = false;
  bool Unorm16 = false;
  int AtlasBytesPerTexel = 0;
};

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

// The last image cast, and what it was cast from: a frame from the same
// state but cut fields recasts only where their modified bricks project.
struct KeptImage
{
  vtkSmartPointer<vtkOpenGLFramebufferObject> Framebuffer;
  vtkSmartPointer<vtkTextureObject> Color;
  vtkSmartPointer<vtkTextureObject> Depth;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  bool Valid = false;
  int Width = 0;
  int Height = 0;
  double WorldToNDC[16] = {};
  vtkMTimeType SceneVersion = 0;
  vtkMTimeType AnatomyVersion = 0;
  vtkMTimeType LabelVersion = 0;
  std::string ProgramKey;
  bool EmptySpaceSkipping = true;
  // Internals::OpaqueDepthVersion when it was cast.
  vtkTypeUInt64 OpaqueDepthVersion = 0;
  std::vector<vtkVolumeCutField*> Fields;
  std::vector<vtkTypeUInt64> Stamps;
};
}

//------------------------------------------------------------------------------
struct vtkVolumeCutOpenGLRayCaster::Internals
{
  vtkOpenGLRenderWindow* Context = nullptr;
  vtkSmartPointer<vtkTextureObject> Anatomy;
  vtkSmartPointer<vtkTextureObject> Labels;
  vtkSmartPointer<vtkTextureObject> Fractions;
  vtkSmartPointer<vtkTextureObject> Styles;
  vtkSmartPointer<vtkTextureObject> Blocks;
  // Per 2 x 2 x 2 cells, a bit per cell that may hold a visible object
  // (vtkVolumeCutEmptySpace's bytes), and whether rays walk them.
  vtkSmartPointer<vtkTextureObject> Cells;
  bool CellWalk = false;
  vtkSmartPointer<vtkTextureObject> Transfer;
  vtkSmartPointer<vtkTextureObject> OpaqueDepth;
  CutTextures Cuts[MaximumNumberOfCutFields];
  KeptImage Kept;
  // What the opaque depth texture holds (it travels only when that changes),
  // and a count of its uploads: the kept image knows by it whether the
  // depth it was cast against is still the one in use.
  bool UploadedHadOpaqueDepth = false;
  std::vector<float> UploadedOpaqueDepth;
  vtkTypeUInt64 OpaqueDepthVersion = 0;
  vtkMTimeType AnatomyVersion = 0;
  vtkMTimeType LabelVersion = 0;
  // How the CT and labels were uploaded: NormalizedTextures then, the CT's
  // format and the values that turn texels back into CT values and labels.
  bool TexturesNormalized = false;
  bool AnatomyUnorm16 = false;
  bool FractionsUnorm16 = false;
  float AnatomyMinimum = 0.f;
  float LabelScale = 1.f;
  vtkMTimeType SceneVersion = 0;
  // The texture unit's interpolation error in this context (-1: it cannot
  // filter R16), measured once a context: a driver that cannot is not
  // probed again every frame.
  double FilterWeightError = -1.0;
  bool FilterWeightMeasured = false;
  // The program for the features of the last Render, and the quad it draws.
  vtkVolumeCutProgramBuilder Builder;
  std::string BuiltFeatures;
  bool BuildChecked = false;
  bool FirstDrawTimed = false;
  vtkSmartPointer<vtkOpenGLVertexArrayObject> QuadVAO;
  vtkShaderProgram* QuadProgram = nullptr;
  // Set when a build exceeded the time limit: the GPU path stays off.
  std::string TimedOutMessage;
  std::string ReportedCacheWarning;

  void Release(vtkWindow* window)
  {
    for (vtkTextureObject* texture : { this->Anatomy.GetPointer(), this->Labels.GetPointer(), this->Fractions.GetPointer(), this->Styles.GetPointer(),
           this->Blocks.GetPointer(), this->Cells.GetPointer(), this->Transfer.GetPointer(), this->OpaqueDepth.GetPointer() })
    {
      if (texture)
      {
        texture->ReleaseGraphicsResources(window);
      }
    }
    this->Anatomy = this->Labels = this->Fractions = this->Styles = this->Blocks = this->Cells = this->Transfer = this->OpaqueDepth = nullptr;
    for (CutTextures& cut : this->Cuts)
    {
      if (cut.Page)
      {
        cut.Page->ReleaseGraphicsResources(window);
        cut.Atlas->ReleaseGraphicsResources(window);
      }
      cut = CutTextures();
    }
    if (this->QuadVAO)
    {
      this->QuadVAO->ReleaseGraphicsResources();
      this->QuadVAO = nullptr;
    }
    this->QuadProgram = nullptr;
    for (vtkTextureObject* texture : { this->Kept.Color.GetPointer(), this->Kept.Depth.GetPointer() })
    {
      if (texture)
      {
        texture->ReleaseGraphicsResources(window);
      }
    }
    if (this->Kept.Framebuffer)
    {
      this->Kept.Framebuffer->ReleaseGraphicsResources(window);
    }
    if (this->Kept.Quad)
    {
      this->Kept.Quad->ReleaseGraphicsResources(window);
    }
    this->Kept = KeptImage();
    this->UploadedOpaqueDepth.clear();
    // A build under way dies with its context; the next Render starts again.
    this->Builder.Release(window);
    this->BuiltFeatures.clear();
    this->AnatomyVersion = 0;
    this->LabelVersion = 0;
    this->SceneVersion = 0;
    this->AnatomyUnorm16 = false;
    this->FractionsUnorm16 = false;
    this->FilterWeightError = -1.0;
    this->FilterWeightMeasured = false;
    this->Context = nullptr;
  }

  static std::string Seconds(double value)
  {
    std::ostringstream text;
    text << std::fixed << std::setprecision(value < 10.0 ? 2 : 1) << value << " s";
    return text.str();
  }

  bool ReadyProgram(vtkVolumeCutOpenGLRayCaster* self, vtkOpenGLRenderWindow* window, const vtkVolumeCutShaderComposer::Features& features);

  // A float colour and depth framebuffer of the viewport's size: the
  // kept image holds exactly what the ray caster wrote.
  bool AllocateKeptImage(vtkOpenGLRenderWindow* window, int width, int height)
  {
    KeptImage& kept = this->Kept;
    for (vtkTextureObject* texture : { kept.Color.GetPointer(), kept.Depth.GetPointer() })
    {
      if (texture)
      {
        texture->ReleaseGraphicsResources(window);
      }
    }
    if (kept.Framebuffer)
    {
      kept.Framebuffer->ReleaseGraphicsResources(window);
    }
    kept.Valid = false;
    kept.Width = kept.Height = 0;
    kept.Framebuffer = nullptr;
    kept.Color = vtkSmartPointer<vtkTextureObject>::New();
    kept.Color->SetContext(window);
    kept.Depth = vtkSmartPointer<vtkTextureObject>::New();
    kept.Depth->SetContext(window);
    for (vtkTextureObject* texture : { kept.Color.GetPointer(), kept.Depth.GetPointer() })
    {
      texture->SetWrapS(vtkTextureObject::ClampToEdge);
      texture->SetWrapT(vtkTextureObject::ClampToEdge);
      texture->SetMinificationFilter(vtkTextureObject::Nearest);
      texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    }
    if (!kept.Color->Allocate2D(width, height, 4, VTK_FLOAT) || !kept.Depth->AllocateDepth(width, height, vtkTextureObject::Float32))
    {
      kept.Color = kept.Depth = nullptr;
      return false;
    }
    auto framebuffer = vtkSmartPointer<vtkOpenGLFramebufferObject>::New();
    framebuffer->SetContext(window);
    vtkOpenGLState* state = window->GetState();
    state->PushFramebufferBindings();
    framebuffer->Bind();
    framebuffer->AddColorAttachment(0, kept.Color);
    framebuffer->AddDepthAttachment(kept.Depth);
    framebuffer->ActivateDrawBuffers(1);
    const char* description = nullptr;
    const bool complete = vtkOpenGLFramebufferObject::GetFrameBufferStatus(vtkOpenGLFramebufferObject::GetDrawMode(), description);
    state->PopFramebufferBindings();
    if (!complete)
    {
      framebuffer->ReleaseGraphicsResources(window);
      kept.Color = kept.Depth = nullptr;
      return false;
    }
    kept.Framebuffer = framebuffer;
    kept.Width = width;
    kept.Height = height;
    return true;
  }

  // Cast the rays of region (x0, y0, x1, y1 of the viewport) into the kept
  // image with the program bound; the rest of it stays as it was.
  void CastIntoKeptImage(vtkOpenGLRenderWindow* window, const int region[4])
  {
    vtkOpenGLState* state = window->GetState();
    state->PushFramebufferBindings();
    this->Kept.Framebuffer->Bind();
    this->Kept.Framebuffer->ActivateDrawBuffers(1);
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
      state->vtkglViewport(0, 0, this->Kept.Width, this->Kept.Height);
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
      this->QuadVAO->Bind();
      vtkOpenGLRenderUtilities::DrawFullScreenQuad();
      this->QuadVAO->Release();
    }
    state->PopFramebufferBindings();
  }

  // Draw the kept image into the window's viewport as the ray caster would.
  bool DrawKeptImage(vtkOpenGLRenderWindow* window)
  {
    KeptImage& kept = this->Kept;
    if (!kept.Quad)
    {
      kept.Quad.reset(new vtkOpenGLQuadHelper(
        window, vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(), KeptImageFragmentShader, ""));
    }
    if (!kept.Quad->Program || !kept.Quad->Program->GetCompiled())
    {
      return false;
    }
    window->GetShaderCache()->ReadyShaderProgram(kept.Quad->Program);
    kept.Color->Activate();
    kept.Depth->Activate();
    kept.Quad->Program->SetUniformi("colorTexture", kept.Color->GetTextureUnit());
    kept.Quad->Program->SetUniformi("depthTexture", kept.Depth->GetTextureUnit());
    DrawSurfaceQuad(window, kept.Quad.get());
    kept.Color->Deactivate();
    kept.Depth->Deactivate();
    return true;
  }

  static vtkSmartPointer<vtkTextureObject> Texture3D(
    vtkOpenGLRenderWindow* window, int x, int y, int z, int components, const float* data)
  {
    return Texture3D(window, x, y, z, components, VTK_FLOAT, 0, data);
  }

  // Unsigned normalized integers (GL_R8 from unsigned char, GL_R16 or
  // GL_RGBA16 from unsigned short) or floats (internalFormat 0: VTK's choice
  // for the type, R32F/RGBA32F for floats).
  static vtkSmartPointer<vtkTextureObject> Texture3D(vtkOpenGLRenderWindow* window, int x, int y, int z, int components,
    int vtkType, unsigned int internalFormat, const void* data)
  {
    auto texture = vtkSmartPointer<vtkTextureObject>::New();
    texture->SetContext(window);
    texture->SetWrapS(vtkTextureObject::ClampToEdge);
    texture->SetWrapT(vtkTextureObject::ClampToEdge);
    texture->SetWrapR(vtkTextureObject::ClampToEdge);
    texture->SetMinificationFilter(vtkTextureObject::Nearest);
    texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    if (internalFormat != 0)
    {
      texture->SetInternalFormat(internalFormat);
      texture->SetFormat(components == 4 ? GL_RGBA : GL_RED);
    }
    if (!texture->Create3DFromRaw(x, y, z, components, vtkType, const_cast<void*>(data)))
    {
      return nullptr;
    }
    return texture;
  }

  // Texel fetches ignore the filter, so one texture serves both the
  // texture unit's interpolation and the shader's exact per-texel reads.
  static void SetLinearFiltering(vtkTextureObject* texture, bool linear)
  {
    const int filter = linear ? vtkTextureObject::Linear : vtkTextureObject::Nearest;
    texture->SetMinificationFilter(filter);
    texture->SetMagnificationFilter(filter);
  }

  // Bytes per voxel of the first component of a 3D texture as the driver
  // stores it (0 where the driver made none, e.g. a format it does not offer).
  static int BytesPerVoxel(vtkTextureObject* texture)
  {
    GLint bits = 0;
    texture->Activate();
    glGetTexLevelParameteriv(GL_TEXTURE_3D, 0, GL_TEXTURE_RED_SIZE, &bits);
    texture->Deactivate();
    return bits / 8;
  }

  static vtkSmartPointer<vtkTextureObject> Texture2D(vtkOpenGLRenderWindow* window, int x, int y, int components, const float* data)
  {
    auto texture = vtkSmartPointer<vtkTextureObject>::New();
    texture->SetContext(window);
    texture->SetWrapS(vtkTextureObject::ClampToEdge);
    texture->SetWrapT(vtkTextureObject::ClampToEdge);
    texture->SetMinificationFilter(vtkTextureObject::Nearest);
    texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    if (!texture->Create2DFromRaw(x, y, components, VTK_FLOAT, const_cast<float*>(data)))
    {
      return nullptr;
    }
    return texture;
  }

  // The largest difference between the texture unit's linear interpolation
  // of two R16 texels, 0 and 65535, and the exact lerp, over 1021 points
  // between them (a fraction of the texels' difference: 2^-9 for weights
  // rounded to 8 bits, about 1e-7 for float weights); -1 where the driver
  // cannot filter R16 or draw into a float target.
  double MeasureFilterWeightError(vtkOpenGLRenderWindow* window)
  {
    constexpr int points = 1021;
    const unsigned short texels[2] = { 0, 65535 };
    vtkSmartPointer<vtkTextureObject> probe = Texture3D(window, 2, 1, 1, 1, VTK_UNSIGNED_SHORT, GL_R16, texels);
    if (!probe)
    {
      return -1.0;
    }
    SetLinearFiltering(probe, true);
    auto target = vtkSmartPointer<vtkTextureObject>::New();
    target->SetContext(window);
    target->SetMinificationFilter(vtkTextureObject::Nearest);
    target->SetMagnificationFilter(vtkTextureObject::Nearest);
    double error = -1.0;
    if (BytesPerVoxel(probe) == 2 && target->Allocate2D(points, 1, 1, VTK_FLOAT))
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

  // Bring one cut field's page table and atlas up to date; returns the
  // number of bricks uploaded, or -1 when a texture cannot be made.
  vtkIdType UpdateCut(vtkOpenGLRenderWindow* window, CutTextures& cut, vtkVolumeCutField* field, bool normalized)
  {
    const int* brickDims = field->GetBrickDimensions();
    const vtkIdType brickCount = static_cast<vtkIdType>(brickDims[0]) * brickDims[1] * brickDims[2];
    const int* dims = field->GetDimensions();
    const bool sameField = cut.Field == field && cut.Page && cut.Dimensions[0] == dims[0] && cut.Dimensions[1] == dims[1] &&
      cut.Dimensions[2] == dims[2] && cut.Unorm16Requested == normalized;
    // The counter first: a brick stamped after it is listed next time.
    const vtkTypeUInt64 stamp = field->GetCurrentStamp();
    vtkNew<vtkIdList> modified;
    field->GetBricksModifiedSince(sameField ? cut.Stamp : 0, modified);
    if (sameField && modified->GetNumberOfIds() == 0)
    {
      cut.Stamp = stamp;
      return 0;
    }
    // Slots needed: those in use plus the new bricks.
    int newBricks = 0;
    if (sameField)
    {
      for (vtkIdType n = 0; n < modified->GetNumberOfIds(); ++n)
      {
        newBricks += cut.SlotOfBrick[modified->GetId(n)] < 0 ? 1 : 0;
      }
    }
    const bool rebuild = !sameField || cut.UsedSlots + newBricks > cut.SlotsPerAxis * cut.SlotsPerAxis * cut.SlotsPerAxis;
    if (rebuild)
    {
      if (sameField)
      {
        // The atlas is full: start again with room to grow, uploading every brick.
        field->GetBricksModifiedSince(0, modified);
      }
      const vtkIdType needed = std::max<vtkIdType>(8, field->GetNumberOfAllocatedBricks() + modified->GetNumberOfIds());
      int slots = static_cast<int>(std::ceil(std::cbrt(1.5 * static_cast<double>(needed))));
      GLint maximum3D = 0;
      glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &maximum3D);
      if (8 * slots > maximum3D || brickDims[0] > maximum3D || brickDims[1] > maximum3D || brickDims[2] > maximum3D)
      {
        return -1;
      }
      std::vector<float> page(brickCount, -1.f);
      cut = CutTextures();
      cut.Page = Texture3D(window, brickDims[0], brickDims[1], brickDims[2], 1, page.data());
      const size_t atlasTexels = static_cast<size_t>(8 * slots) * 8 * slots * 8 * slots;
      if (normalized)
      {
        // Distances are whole quanta, -32767..32767 (32767: no brick there):
        // shifted by 32768 they fit R16 exactly, half the floats' memory and upload.
        std::vector<unsigned short> empty(atlasTexels, static_cast<unsigned short>(32767 + CutAtlasOffset));
        cut.Atlas = Texture3D(window, 8 * slots, 8 * slots, 8 * slots, 1, VTK_UNSIGNED_SHORT, GL_R16, empty.data());
        if (cut.Atlas && BytesPerVoxel(cut.Atlas) == 0)
        {
          cut.Atlas->ReleaseGraphicsResources(window);
          cut.Atlas = nullptr;
        }
        cut.Unorm16 = cut.Atlas != nullptr;
      }
      if (!cut.Atlas)
      {
        std::vector<float> empty(atlasTexels, 32767.f);
        cut.Atlas = Texture3D(window, 8 * slots, 8 * slots, 8 * slots, 1, empty.data());
      }
      if (!cut.Page || !cut.Atlas)
      {
        cut = CutTextures();
        return -1;
      }
      cut.Unorm16Requested = normalized;
      cut.AtlasBytesPerTexel = BytesPerVoxel(cut.Atlas);
      cut.Field = field;
      cut.SlotsPerAxis = slots;
      cut.SlotOfBrick.assign(brickCount, -1);
      std::copy(dims, dims + 3, cut.Dimensions);
    }
    std::vector<short> values(vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize * vtkVolumeCutField::BrickSize);
    std::vector<float> floats(cut.Unorm16 ? 0 : values.size());
    std::vector<unsigned short> shifted(cut.Unorm16 ? values.size() : 0);
    vtkIdType uploaded = 0;
    for (vtkIdType n = 0; n < modified->GetNumberOfIds(); ++n)
    {
      const vtkIdType id = modified->GetId(n);
      field->CopyBrick(id, values.data());
      if (cut.Unorm16)
      {
        std::transform(values.begin(), values.end(), shifted.begin(),
          [](short value) { return static_cast<unsigned short>(value + CutAtlasOffset); });
      }
      else
      {
        std::copy(values.begin(), values.end(), floats.begin());
      }
      int& slot = cut.SlotOfBrick[id];
      if (slot < 0)
      {
        slot = cut.UsedSlots++;
        const float slotValue = static_cast<float>(slot);
        const int b[3] = { static_cast<int>(id % brickDims[0]), static_cast<int>((id / brickDims[0]) % brickDims[1]),
          static_cast<int>(id / (static_cast<vtkIdType>(brickDims[0]) * brickDims[1])) };
        cut.Page->Bind();
        glTexSubImage3D(GL_TEXTURE_3D, 0, b[0], b[1], b[2], 1, 1, 1, GL_RED, GL_FLOAT, &slotValue);
      }
      const int s = cut.SlotsPerAxis;
      cut.Atlas->Bind();
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      if (cut.Unorm16)
      {
        glTexSubImage3D(GL_TEXTURE_3D, 0, 8 * (slot % s), 8 * ((slot / s) % s), 8 * (slot / (s * s)), 8, 8, 8, GL_RED,
          GL_UNSIGNED_SHORT, shifted.data());
      }
      else
      {
        glTexSubImage3D(GL_TEXTURE_3D, 0, 8 * (slot % s), 8 * ((slot / s) % s), 8 * (slot / (s * s)), 8, 8, 8, GL_RED, GL_FLOAT,
          floats.data());
      }
      ++uploaded;
    }
    cut.Stamp = stamp;
    return uploaded;
  }
};

//------------------------------------------------------------------------------
bool vtkVolumeCutOpenGLRayCaster::Internals::ReadyProgram(
  vtkVolumeCutOpenGLRayCaster* self, vtkOpenGLRenderWindow* window, const vtkVolumeCutShaderComposer::Features& features)
{
  auto seconds = &Internals::Seconds;
  if (!this->TimedOutMessage.empty())
  {
    self->ProgramStatus = ProgramTimedOut;
    self->LastErrorMessage = this->TimedOutMessage;
    return false;
  }
  const std::string key = vtkVolumeCutShaderComposer::Describe(features) + '\n' + features.ExtraDeclarations;
  if (key != this->BuiltFeatures || this->Builder.GetStatus() == vtkVolumeCutProgramBuilder::Empty)
  {
    // Other features: another program (a failed one is not tried again
    // until the features change, so a rejecting driver costs one build).
    const std::string fragment = vtkVolumeCutShaderComposer::FragmentShader(features);
    self->ProgramSourceLength = static_cast<vtkIdType>(fragment.size());
    self->ProgramFeatures = vtkVolumeCutShaderComposer::Describe(features);
    this->BuiltFeatures = key;
    this->BuildChecked = false;
    this->FirstDrawTimed = false;
    this->QuadProgram = nullptr;
    std::string directory;
    if (self->ProgramCache)
    {
      directory = self->ProgramCacheDirectory.empty() ? DefaultProgramCacheDirectory() : self->ProgramCacheDirectory;
    }
    this->Builder.Start(window, vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader(), fragment, directory);
  }
  const vtkVolumeCutProgramBuilder::Status status = this->Builder.Poll();
  if (!this->FirstDrawTimed)
  {
    self->LastProgramBuildTime = this->Builder.GetBuildSeconds();
  }
  self->LastProgramLoadedFromCache = this->Builder.GetLoadedFromCache();
  const std::string& cacheWarning = this->Builder.GetCacheWarning();
  if (!cacheWarning.empty() && cacheWarning != this->ReportedCacheWarning)
  {
    // Once: the program is rebuilt from source and stored again.
    vtkWarningWithObjectMacro(self, "Render: " << cacheWarning);
    this->ReportedCacheWarning = cacheWarning;
  }
  const std::string limit = seconds(self->ProgramBuildTimeLimit);
  switch (status)
  {
    case vtkVolumeCutProgramBuilder::Pending:
      if (self->LastProgramBuildTime <= self->ProgramBuildTimeLimit)
      {
        self->ProgramStatus = ProgramPending;
        self->LastErrorMessage = "the GPU program is being built (" + seconds(self->LastProgramBuildTime) + " so far, limit " + limit + ")";
        return false;
      }
      this->TimedOutMessage = "the GPU program was not built after " + seconds(self->LastProgramBuildTime) + " on " +
        self->DriverDescription + ", over ProgramBuildTimeLimit (" + limit + "); cuts are drawn on the CPU";
      this->Builder.Release(window);
      self->ProgramStatus = ProgramTimedOut;
      self->LastErrorMessage = this->TimedOutMessage;
      return false;
    case vtkVolumeCutProgramBuilder::Failed:
      self->ProgramStatus = ProgramFailed;
      self->LastErrorMessage = "the OpenGL driver (" + self->DriverDescription + ") rejects the GPU program (" + self->ProgramFeatures +
        "): " + this->Builder.GetError();
      return false;
    case vtkVolumeCutProgramBuilder::Ready:
      break;
    default:
      self->ProgramStatus = ProgramNone;
      self->LastErrorMessage = "no GPU program";
      return false;
  }
  if (!this->BuildChecked)
  {
    this->BuildChecked = true;
    if (self->LastProgramBuildTime > self->ProgramBuildTimeLimit)
    {
      // The build blocked the view for longer than allowed: the next one
      // (other features, another start without the cache) would too.
      this->TimedOutMessage = std::string(self->LastProgramLoadedFromCache ? "loading" : "building") + " the GPU program took " +
        seconds(self->LastProgramBuildTime) + " on " + self->DriverDescription + ", over ProgramBuildTimeLimit (" + limit +
        "); cuts are drawn on the CPU";
      this->Builder.Release(window);
      self->ProgramStatus = ProgramTimedOut;
      self->LastErrorMessage = this->TimedOutMessage;
      return false;
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
      self->ProgramStatus = ProgramFailed;
      self->LastErrorMessage = "the full-screen quad cannot be set up for the GPU program";
      return false;
    }
    this->QuadProgram = program;
  }
  self->ProgramStatus = ProgramReady;
  return true;
}

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
  vtkIdType texels = 0;
  for (const CutTextures& cut : this->Impl->Cuts)
  {
    if (cut.Atlas)
    {
      texels += static_cast<vtkIdType>(cut.Atlas->GetWidth()) * cut.Atlas->GetHeight() * cut.Atlas->GetDepth();
    }
  }
  return texels;
}

//------------------------------------------------------------------------------
size_t vtkVolumeCutOpenGLRayCaster::GetTextureMemorySize() const
{
  size_t bytes = 0;
  auto add = [&bytes](vtkTextureObject* texture) {
    if (texture)
    {
      // The size of the uploaded type is the size of each texture's format.
      bytes += static_cast<size_t>(texture->GetWidth()) * texture->GetHeight() * std::max(1u, texture->GetDepth()) *
        texture->GetComponents() * vtkAbstractArray::GetDataTypeSize(texture->GetVTKDataType());
    }
  };
  add(this->Impl->Anatomy);
  add(this->Impl->Labels);
  add(this->Impl->Fractions);
  add(this->Impl->Styles);
  add(this->Impl->Blocks);
  add(this->Impl->Cells);
  add(this->Impl->Transfer);
  add(this->Impl->OpaqueDepth);
  add(this->Impl->Kept.Color);
  add(this->Impl->Kept.Depth);
  for (const CutTextures& cut : this->Impl->Cuts)
  {
    add(cut.Page);
    add(cut.Atlas);
  }
  return bytes;
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
  if (!impl.TimedOutMessage.empty())
  {
    // Nothing to upload for a path that stays off.
    this->ProgramStatus = ProgramTimedOut;
    this->LastErrorMessage = impl.TimedOutMessage;
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

  // Each texture travels when what it holds changed: the CT with its values
  // or grid, labels and fractions with them, the small tables with anything.
  const size_t voxels = static_cast<size_t>(dims[0]) * dims[1] * dims[2];
  const bool anatomyChanged =
    !impl.Anatomy || impl.AnatomyVersion != view.AnatomyVersion || impl.TexturesNormalized != this->NormalizedTextures;
  if (anatomyChanged)
  {
    impl.Anatomy = nullptr;
    impl.AnatomyUnorm16 = false;
    impl.TexturesNormalized = this->NormalizedTextures;
    std::vector<unsigned short> texels;
    float minimum = 0.f;
    if (this->NormalizedTextures && ToUnorm16(view.Values, voxels, minimum, texels))
    {
      impl.Anatomy = Internals::Texture3D(window, dims[0], dims[1], dims[2], 1, VTK_UNSIGNED_SHORT, GL_R16, texels.data());
      if (impl.Anatomy && Internals::BytesPerVoxel(impl.Anatomy) == 0)
      {
        // A driver without R16 textures: the floats, as before.
        impl.Anatomy->ReleaseGraphicsResources(window);
        impl.Anatomy = nullptr;
      }
      impl.AnatomyUnorm16 = impl.Anatomy != nullptr;
      impl.AnatomyMinimum = minimum;
    }
    if (!impl.Anatomy)
    {
      impl.Anatomy = Internals::Texture3D(window, dims[0], dims[1], dims[2], 1, view.Values);
    }
    this->AnatomyTextureBytesPerVoxel = impl.Anatomy ? Internals::BytesPerVoxel(impl.Anatomy) : 0;
    if (this->AnatomyTextureBytesPerVoxel == 0)
    {
      // No texture, or the driver could not allocate it (GL_OUT_OF_MEMORY).
      if (impl.Anatomy)
      {
        impl.Anatomy->ReleaseGraphicsResources(window);
        impl.Anatomy = nullptr;
      }
      this->LastErrorMessage = "the CT does not fit in GPU memory as a float 3D texture";
      return false;
    }
    impl.AnatomyVersion = view.AnatomyVersion;
  }
  if (anatomyChanged || !impl.Labels || !impl.Fractions || impl.LabelVersion != view.LabelVersion)
  {
    impl.Labels = nullptr;
    if (view.Labels && this->NormalizedTextures)
    {
      // Labels are 0..65535: R16 is always exact, R8 when they fit in a byte.
      const unsigned short largest = *std::max_element(view.Labels, view.Labels + voxels);
      if (largest <= 255)
      {
        const std::vector<unsigned char> bytes(view.Labels, view.Labels + voxels);
        impl.Labels = Internals::Texture3D(window, dims[0], dims[1], dims[2], 1, VTK_UNSIGNED_CHAR, GL_R8, bytes.data());
        impl.LabelScale = 255.f;
      }
      else
      {
        impl.Labels = Internals::Texture3D(window, dims[0], dims[1], dims[2], 1, VTK_UNSIGNED_SHORT, GL_R16, view.Labels);
        impl.LabelScale = 65535.f;
      }
      if (impl.Labels && Internals::BytesPerVoxel(impl.Labels) == 0)
      {
        impl.Labels->ReleaseGraphicsResources(window);
        impl.Labels = nullptr;
      }
    }
    if (!impl.Labels)
    {
      std::vector<float> labels(view.Labels ? voxels : 8, 0.f);
      if (view.Labels)
      {
        std::copy(view.Labels, view.Labels + voxels, labels.begin());
      }
      impl.Labels = view.Labels ? Internals::Texture3D(window, dims[0], dims[1], dims[2], 1, labels.data())
                                : Internals::Texture3D(window, 2, 2, 2, 1, labels.data());
      impl.LabelScale = 1.f;
    }
    this->LabelTextureBytesPerVoxel = impl.Labels && view.Labels ? Internals::BytesPerVoxel(impl.Labels) : 0;
    // Up to four segments' fractions, one per channel: RGBA16, as the CPU
    // holds them in 0..1 (each within 1/131070 of its value, far inside the
    // CPU/GPU tolerance of the mapper tests), else RGBA32F.
    impl.Fractions = nullptr;
    impl.FractionsUnorm16 = false;
    if (!view.Fractions.empty() && this->NormalizedTextures)
    {
      std::vector<unsigned short> quantized(4 * voxels, 0);
      for (size_t i = 0; i < view.Fractions.size(); ++i)
      {
        const float* fraction = view.Fractions[i].second;
        for (size_t n = 0; n < voxels; ++n)
        {
          quantized[4 * n + i] = static_cast<unsigned short>(std::min(std::max(fraction[n], 0.f), 1.f) * 65535.f + 0.5f);
        }
      }
      impl.Fractions = Internals::Texture3D(window, dims[0], dims[1], dims[2], 4, VTK_UNSIGNED_SHORT, GL_RGBA16, quantized.data());
      if (impl.Fractions && Internals::BytesPerVoxel(impl.Fractions) == 0)
      {
        impl.Fractions->ReleaseGraphicsResources(window);
        impl.Fractions = nullptr;
      }
      impl.FractionsUnorm16 = impl.Fractions != nullptr;
    }
    if (!impl.Fractions)
    {
      std::vector<float> fractions(view.Fractions.empty() ? 32 : 4 * voxels, 0.f);
      for (size_t i = 0; i < view.Fractions.size(); ++i)
      {
        for (size_t n = 0; n < voxels; ++n)
        {
          fractions[4 * n + i] = view.Fractions[i].second[n];
        }
      }
      impl.Fractions = view.Fractions.empty() ? Internals::Texture3D(window, 2, 2, 2, 4, fractions.data())
                                              : Internals::Texture3D(window, dims[0], dims[1], dims[2], 4, fractions.data());
    }
    this->FractionTextureBytesPerVoxel =
      impl.Fractions && !view.Fractions.empty() ? 4 * Internals::BytesPerVoxel(impl.Fractions) : 0;
    if (!impl.Labels || !impl.Fractions)
    {
      this->LastErrorMessage = "the label map or fractional labelmaps do not fit in GPU memory";
      impl.Labels = impl.Fractions = nullptr;
      return false;
    }
    impl.LabelVersion = view.LabelVersion;
    impl.SceneVersion = 0; // the tables follow
  }
  if (impl.SceneVersion != view.Version)
  {
    std::vector<float> styles(12 * view.Styles.size());
    const int styleCount = static_cast<int>(view.Styles.size());
    for (int label = 0; label < styleCount; ++label)
    {
      std::copy(view.Styles[label].begin(), view.Styles[label].begin() + 4, styles.begin() + 4 * label);
      std::copy(view.Styles[label].begin() + 4, view.Styles[label].begin() + 8, styles.begin() + 4 * (styleCount + label));
      std::copy(view.Styles[label].begin() + 8, view.Styles[label].end(), styles.begin() + 4 * (2 * styleCount + label));
    }
    impl.Styles = Internals::Texture2D(window, styleCount, 3, 4, styles.data());
    const int* bd = view.BlockDimensions;
    const size_t blocks = static_cast<size_t>(bd[0]) * bd[1] * bd[2];
    std::vector<float> blockData(2 * blocks);
    for (size_t n = 0; n < blocks; ++n)
    {
      // The reach (0 for an occupied block) says both whether a block is
      // empty and how far around it the ray may jump.
      blockData[2 * n] = view.BlockOccupied[n] ? 0.f : float(std::max<int>(view.BlockReach[n], 1));
      blockData[2 * n + 1] = std::isfinite(view.BlockLipschitz[n]) ? view.BlockLipschitz[n] : 1e30f;
    }
    impl.Blocks = Internals::Texture3D(window, bd[0], bd[1], bd[2], 2, blockData.data());
    // The cells' bytes as the CPU holds them; one byte with every cell kept
    // where cells are not classified (the walk is off then).
    const int* gd = view.CellGroupDimensions;
    const unsigned char everyCell = 0xff;
    impl.Cells = view.CellGroups
      ? Internals::Texture3D(window, gd[0], gd[1], gd[2], 1, VTK_UNSIGNED_CHAR, GL_R8, view.CellGroups)
      : Internals::Texture3D(window, 1, 1, 1, 1, VTK_UNSIGNED_CHAR, GL_R8, &everyCell);
    impl.CellWalk = view.CellGroups != nullptr;
    if (impl.Cells && Internals::BytesPerVoxel(impl.Cells) != 1)
    {
      // A driver without exact R8 texels: no walk rather than a wrong one.
      impl.Cells->ReleaseGraphicsResources(window);
      impl.Cells = Internals::Texture3D(window, 1, 1, 1, 1, VTK_UNSIGNED_CHAR, GL_R8, &everyCell);
      impl.CellWalk = false;
    }
    std::vector<float> transfer(4 * std::max(view.TableSize, 2), 0.f);
    if (view.ColorTable && view.OpacityTable)
    {
      for (int n = 0; n < view.TableSize; ++n)
      {
        std::copy(view.ColorTable + 3 * n, view.ColorTable + 3 * n + 3, transfer.begin() + 4 * n);
        transfer[4 * n + 3] = view.OpacityTable[n];
      }
    }
    impl.Transfer = Internals::Texture2D(window, std::max(view.TableSize, 2), 1, 4, transfer.data());
    if (!impl.Styles || !impl.Blocks || !impl.Cells || !impl.Transfer)
    {
      this->LastErrorMessage = "the lookup tables do not fit in GPU memory";
      return false;
    }
    impl.SceneVersion = view.Version;
  }

  // The counters before the upload: a brick stamped after them is recast next time.
  std::vector<vtkTypeUInt64> currentStamps(cuts);
  for (int n = 0; n < cuts; ++n)
  {
    currentStamps[n] = view.CutFields[n]->GetCurrentStamp();
  }
  // Cut fields: only modified bricks travel.
  for (int n = 0; n < cuts; ++n)
  {
    const vtkIdType uploaded = impl.UpdateCut(window, impl.Cuts[n], view.CutFields[n], this->NormalizedTextures);
    if (uploaded < 0)
    {
      this->LastErrorMessage = "cut field " + std::to_string(n) + " does not fit in GPU memory";
      return false;
    }
    this->NumberOfBricksUploaded += uploaded;
  }
  this->TotalNumberOfBricksUploaded += this->NumberOfBricksUploaded;

  const size_t pixels = static_cast<size_t>(width) * height;
  const bool sameDepth = impl.UploadedHadOpaqueDepth == (opaqueDepth != nullptr) &&
    (!opaqueDepth ||
      (impl.UploadedOpaqueDepth.size() == pixels &&
        std::memcmp(opaqueDepth, impl.UploadedOpaqueDepth.data(), pixels * sizeof(float)) == 0));
  if (!impl.OpaqueDepth || !sameDepth)
  {
    std::vector<float> depth(pixels, 1.f);
    if (opaqueDepth)
    {
      std::copy(opaqueDepth, opaqueDepth + pixels, depth.begin());
    }
    impl.OpaqueDepth = Internals::Texture2D(window, width, height, 1, depth.data());
    if (!impl.OpaqueDepth)
    {
      this->LastErrorMessage = "no memory for the depth texture";
      return false;
    }
    impl.UploadedHadOpaqueDepth = opaqueDepth != nullptr;
    impl.UploadedOpaqueDepth.clear();
    if (opaqueDepth)
    {
      impl.UploadedOpaqueDepth.assign(opaqueDepth, opaqueDepth + pixels);
    }
    ++impl.OpaqueDepthVersion;
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
  features.AnatomyUnorm16 = impl.AnatomyUnorm16;
  features.CutAtlasUnorm16.clear();
  for (int n = 0; n < cuts; ++n)
  {
    features.CutAtlasUnorm16.push_back(impl.Cuts[n].Unorm16);
  }
  this->CutAtlasTextureBytesPerVoxel = cuts > 0 ? impl.Cuts[0].AtlasBytesPerTexel : 0;
  // Only 16-bit normalized textures are filtered (R32F is not filterable
  // everywhere: OES_texture_float_linear; labels are never interpolated),
  // and only by a texture unit that weights texels finely enough.
  if (this->HardwareFiltering && !impl.FilterWeightMeasured && (impl.AnatomyUnorm16 || impl.FractionsUnorm16))
  {
    impl.FilterWeightError = impl.MeasureFilterWeightError(window);
    impl.FilterWeightMeasured = true;
  }
  this->FilterWeightError = impl.FilterWeightError;
  const bool precise = this->HardwareFiltering && impl.FilterWeightError >= 0.0 && impl.FilterWeightError <= this->MaximumFilterWeightError;
  this->AnatomyHardwareFiltered = precise && impl.AnatomyUnorm16;
  this->FractionsHardwareFiltered = precise && impl.FractionsUnorm16;
  Internals::SetLinearFiltering(impl.Anatomy, this->AnatomyHardwareFiltered);
  Internals::SetLinearFiltering(impl.Fractions, this->FractionsHardwareFiltered);
  features.AnatomyFiltered = this->AnatomyHardwareFiltered;
  features.FractionsFiltered = this->FractionsHardwareFiltered;
  features.FilterWeightBits = this->EmulatedFilterWeightBits;
  if (!impl.ReadyProgram(this, window, features))
  {
    return false;
  }
  vtkShaderProgram* program = impl.QuadProgram;

  vtkVolumeCutRayCaster* s = scene;
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
  const float blockDimensions[3] = { float(view.BlockDimensions[0]), float(view.BlockDimensions[1]), float(view.BlockDimensions[2]) };
  program->SetUniform3f("blockDimensionsF", blockDimensions);
  const float size[2] = { float(width), float(height) };
  program->SetUniform2f("viewportSize", size);
  program->SetUniformi("hasLabels", view.Labels || !view.Fractions.empty() ? 1 : 0);
  program->SetUniformi("hasLabelMap", view.Labels ? 1 : 0);
  program->SetUniformf("anatomyMinimum", impl.AnatomyMinimum);
  program->SetUniformf("labelScale", impl.LabelScale);
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
  program->SetUniformi("cellWalk", impl.CellWalk && this->EmptySpaceSkipping ? 1 : 0);
  // A straight ray crosses fewer cells than the sum of the cell grid's sides.
  program->SetUniformi("cellWalkSteps", dims[0] + dims[1] + dims[2]);
  program->SetUniformi("reachJumps", this->EmptySpaceSkipping ? 1 : 0);
  program->SetUniformi("exactHiddenBorders", this->EmptySpaceSkipping ? 1 : 0);
  program->SetUniformi("cavityJumps", this->EmptySpaceSkipping ? 1 : 0);
  // Cell pieces of one interval in the exact hidden-border test: a uniform
  // bound (a constant would have drivers unroll the loop).
  program->SetUniformi("intervalPieces", 16);
  program->SetUniformi("occlusionDirections", 7);
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

  std::vector<vtkTextureObject*> active;
  auto bindTexture = [&](vtkTextureObject* texture, const char* name) {
    texture->Activate();
    program->SetUniformi(name, texture->GetTextureUnit());
    active.push_back(texture);
  };
  bindTexture(impl.Anatomy, "anatomyTexture");
  bindTexture(impl.Labels, "labelTexture");
  bindTexture(impl.Fractions, "fractionTexture");
  bindTexture(impl.Styles, "styleTexture");
  bindTexture(impl.Blocks, "blockTexture");
  bindTexture(impl.Cells, "cellTexture");
  bindTexture(impl.OpaqueDepth, "opaqueDepthTexture");
  bindTexture(impl.Transfer, "transferTexture");
  for (int n = 0; n < cuts; ++n)
  {
    const std::string index = std::to_string(n);
    CutTextures& cut = impl.Cuts[n];
    bindTexture(cut.Page, ("cutPage" + index).c_str());
    bindTexture(cut.Atlas, ("cutAtlas" + index).c_str());
    const float cutDimensions[3] = { float(cut.Dimensions[0]), float(cut.Dimensions[1]), float(cut.Dimensions[2]) };
    program->SetUniform3f(("cutDimensionsF" + index).c_str(), cutDimensions);
    program->SetUniformi(("cutSlots" + index).c_str(), cut.SlotsPerAxis);
    vtkNew<vtkMatrix4x4> subToWorld;
    view.CutFields[n]->GetSubVoxelIJKToRAS(subToWorld);
    vtkNew<vtkMatrix4x4> worldToSub;
    vtkMatrix4x4::Invert(subToWorld, worldToSub);
    ColumnMajor(&worldToSub->Element[0][0], matrix);
    program->SetUniformMatrix4x4(("worldToSub" + index).c_str(), matrix);
    program->SetUniformf(("cutQuantum" + index).c_str(), static_cast<float>(view.CutFields[n]->GetQuantum()));
    program->SetUniformf(("cutCorrectionReach" + index).c_str(),
      static_cast<float>(view.CutFields[n]->GetCorrectionReach() / view.CutFields[n]->GetQuantum()));
    double spacing[3];
    view.CutFields[n]->GetSubVoxelSpacing(spacing);
    program->SetUniformf(("cutStep" + index).c_str(), static_cast<float>(0.25 * std::min({ spacing[0], spacing[1], spacing[2] })));
  }

  // The kept image is this frame's but where bricks changed when nothing
  // else did since it was cast (the CPU path's conditions for a localized update).
  KeptImage& kept = impl.Kept;
  const bool localized = this->LocalizedUpdates && kept.Valid && kept.Width == width && kept.Height == height &&
    std::equal(worldToNDCValues, worldToNDCValues + 16, kept.WorldToNDC) && kept.SceneVersion == view.Version &&
    kept.AnatomyVersion == view.AnatomyVersion && kept.LabelVersion == view.LabelVersion && kept.ProgramKey == impl.BuiltFeatures &&
    kept.EmptySpaceSkipping == this->EmptySpaceSkipping && kept.Fields == view.CutFields && kept.OpaqueDepthVersion == impl.OpaqueDepthVersion;
  if (!kept.Framebuffer || kept.Width != width || kept.Height != height)
  {
    if (!impl.AllocateKeptImage(window, width, height))
    {
      for (vtkTextureObject* texture : active)
      {
        texture->Deactivate();
      }
      this->LastErrorMessage = "no framebuffer for a " + std::to_string(width) + " x " + std::to_string(height) + " image on the GPU";
      return false;
    }
  }
  int region[4] = { 0, 0, width - 1, height - 1 };
  if (localized)
  {
    region[0] = width;
    region[1] = height;
    region[2] = region[3] = -1;
    const double reach = std::max(features.AmbientOcclusion ? s->GetAmbientOcclusionRadius() : 0.0,
      features.ThinBone ? s->GetThinBoneThickness() : 0.0);
    std::vector<uint8_t> mask(pixels, 0);
    for (int n = 0; n < cuts; ++n)
    {
      vtkVolumeCutLocalizedUpdate::MarkModifiedBricks(
        view.CutFields[n], kept.Stamps[n], reach, worldToNDCValues, width, height, mask, region);
    }
  }
  kept.Valid = false; // until the cast below is done

  const double drawStart = vtkTimerLog::GetUniversalTime();
  if (region[2] >= region[0] && region[3] >= region[1])
  {
    impl.CastIntoKeptImage(window, region);
  }
  if (!impl.FirstDrawTimed)
  {
    // Drivers may compile the machine code at the first draw (llvmpipe
    // does, for seconds): the build ends when the first image is done.
    glFinish();
    impl.FirstDrawTimed = true;
    this->LastProgramBuildTime += vtkTimerLog::GetUniversalTime() - drawStart;
    if (this->LastProgramBuildTime > this->ProgramBuildTimeLimit)
    {
      impl.TimedOutMessage = "building the GPU program and its first image took " + impl.Seconds(this->LastProgramBuildTime) + " on " +
        this->DriverDescription + ", over ProgramBuildTimeLimit (" + impl.Seconds(this->ProgramBuildTimeLimit) +
        "); cuts are drawn on the CPU from the next frame";
    }
  }
  for (vtkTextureObject* texture : active)
  {
    texture->Deactivate();
  }
  kept.Valid = true;
  std::copy(worldToNDCValues, worldToNDCValues + 16, kept.WorldToNDC);
  kept.SceneVersion = view.Version;
  kept.AnatomyVersion = view.AnatomyVersion;
  kept.LabelVersion = view.LabelVersion;
  kept.ProgramKey = impl.BuiltFeatures;
  kept.EmptySpaceSkipping = this->EmptySpaceSkipping;
  kept.Fields = view.CutFields;
  kept.Stamps = currentStamps;
  kept.OpaqueDepthVersion = impl.OpaqueDepthVersion;
  std::copy(region, region + 4, this->UpdatedRegion);
  this->NumberOfPixelsRecast = region[2] >= region[0] && region[3] >= region[1]
    ? static_cast<vtkIdType>(region[2] - region[0] + 1) * (region[3] - region[1] + 1)
    : 0;
  this->LastRenderWasLocalized = localized;
  if (!impl.DrawKeptImage(window))
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
  this->Impl->TimedOutMessage.clear();
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
