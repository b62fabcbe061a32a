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
 */
#ifndef vtkVolumeCutShaderComposer_h
#define vtkVolumeCutShaderComposer_h

#include <string>

class vtkVolumeCutShaderComposer
{
public:
  /// What a program is built for.
  struct Features
  {
    /// Cut fields sampled (each gets its own textures and code).
    int CutFields = 0;
  };

  /// The complete fragment shader for these features.
  static std::string FragmentShader(const Features& features);
};

#endif
