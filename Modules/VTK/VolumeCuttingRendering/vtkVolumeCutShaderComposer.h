// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
// Private to VolumeCuttingRendering (not installed, not wrapped).
/**
 * @class   vtkVolumeCutShaderComposer
 * @brief   Composes vtkVolumeCutOpenGLRayCaster's fragment shader from one GLSL snippet per stage.
 *
 * As VTK's volume mappers compose their shaders (vtkVolumeShaderComposer.h):
 * the skeleton glsl/vtkVolumeCutRayCastFS.glsl (the pixel's ray and the march
 * along it) holds a //VolumeCut::<Stage>::Dec tag per stage of adaptive
 * sampling, each replaced by that stage's snippet, glsl/vtkVolumeCut<Stage>FS.glsl
 * (compiled into the library with vtk_encode_string), and the cut-field
 * snippet is written once per field.
 *
 * A program is specialized to the features in use: the scene's switches
 * (label map, fractional labelmaps, blend mode, thin bone, ambient
 * occlusion, clip planes) become constants the compiler folds, and the
 * snippets of stages not in use (composite, thin bone, ambient occlusion)
 * are left out, so that a driver compiles only what it will run. Loops over
 * sample evaluations take their bounds from uniforms: drivers unroll loops
 * with constant bounds, and unrolled bisections of unrolled classifications
 * took minutes to compile (issue 12).
 */
#ifndef vtkVolumeCutShaderComposer_h
#define vtkVolumeCutShaderComposer_h

#include <string>
#include <vector>

class vtkVolumeCutShaderComposer
{
public:
  /// What a program is built for.
  struct Features
  {
    /// Cut fields sampled (each gets its own textures and code).
    int CutFields = 0;
    /// A label map is sampled.
    bool LabelMap = false;
    /// Segments given as fractional labelmaps (0 to 4).
    int Fractions = 0;
    /// Composite blend (the transfer functions) instead of iso-surfaces.
    bool Composite = false;
    /// Thin-bone shading.
    bool ThinBone = false;
    /// Ambient occlusion.
    bool AmbientOcclusion = false;
    /// Clip planes (0 to 6).
    int ClipPlanes = 0;
    /// The CT is a 16-bit unsigned normalized texture (value - minimum), not R32F.
    bool AnatomyUnorm16 = false;
    /// Per cut field: its atlas is R16 (distance + 32768), not R32F.
    std::vector<bool> CutAtlasUnorm16;
    /// The texture unit interpolates the CT (GL_LINEAR R16), not the shader.
    bool AnatomyFiltered = false;
    /// The texture unit interpolates the fractions (GL_LINEAR RGBA16).
    bool FractionsFiltered = false;
    /// Fractional bits of the shader's own interpolation weights (0: float; tests only).
    int FilterWeightBits = 0;
    /// GLSL added before main() (empty unless the caster was given some).
    std::string ExtraDeclarations;
  };

  /// A short description of the features ("cuts=2 labels fractions=1 iso ... ct16 ct-filtered").
  static std::string Describe(const Features& features);

  /// The complete fragment shader for these features.
  static std::string FragmentShader(const Features& features);
};

#endif
