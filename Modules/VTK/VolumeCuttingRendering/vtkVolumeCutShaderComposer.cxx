// SPDX-FileCopyrightText: VolumeCutting developers
// SPDX-License-Identifier: Apache-2.0
#include "vtkVolumeCutShaderComposer.h"

#include "vtkVolumeCutAmbientOcclusionFS.h"
#include "vtkVolumeCutBorderLocationFS.h"
#include "vtkVolumeCutClassificationFS.h"
#include "vtkVolumeCutCompositeFS.h"
#include "vtkVolumeCutCutFieldFS.h"
#include "vtkVolumeCutCutFieldsFS.h"
#include "vtkVolumeCutEmptySpaceFS.h"
#include "vtkVolumeCutPieceClassificationFS.h"
#include "vtkVolumeCutRayCastFS.h"
#include "vtkVolumeCutShadingFS.h"
#include "vtkVolumeCutThinBoneFS.h"

#include <vtkShaderProgram.h>

#include <algorithm>
#include <utility>

//------------------------------------------------------------------------------
std::string vtkVolumeCutShaderComposer::FragmentShader(const Features& features)
{
  const int cuts = std::max(features.CutFields, 0);
  std::string source = vtkVolumeCutRayCastFS;
  std::string defines =
    "#define NUMBER_OF_CUTS " + std::to_string(cuts) + "\n#define CUT_SLOTS " + std::to_string(std::max(cuts, 1)) + "\n";
  if (features.AnatomyUnorm16)
  {
    defines += "#define ANATOMY_UNORM16\n";
  }
  for (size_t n = 0; n < features.CutAtlasUnorm16.size(); ++n)
  {
    if (features.CutAtlasUnorm16[n])
    {
      defines += "#define CUT_ATLAS_UNORM16_" + std::to_string(n) + "\n";
    }
  }
  if (features.AnatomyFiltered)
  {
    defines += "#define ANATOMY_FILTERED\n";
  }
  if (features.FractionsFiltered)
  {
    defines += "#define FRACTIONS_FILTERED\n";
  }
  if (features.FilterWeightBits > 0)
  {
    defines += "#define FILTER_WEIGHT_STEPS " + std::to_string(1 << std::min(features.FilterWeightBits, 16)) + ".0\n";
  }
  vtkShaderProgram::Substitute(source, "//VTK::Output::Dec", "//VTK::Output::Dec\n" + defines);
  vtkShaderProgram::Substitute(source, "//VolumeCut::Classification::Dec", vtkVolumeCutClassificationFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::CutFields::Dec", vtkVolumeCutCutFieldsFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::EmptySpace::Dec", vtkVolumeCutEmptySpaceFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::BorderLocation::Dec", vtkVolumeCutBorderLocationFS);
  // A stage not in use is a stub of the same signature: its uniforms and
  // loops never reach the compiler.
  vtkShaderProgram::Substitute(source, "//VolumeCut::AmbientOcclusion::Dec",
    features.AmbientOcclusion ? vtkVolumeCutAmbientOcclusionFS
                              : "const int ambientOcclusion = 0;\nfloat occlusion(vec3 index, vec3 normal) { return 0.0; }\n"
                                "float cavityShade(vec3 index, vec3 view) { return 1.0; }\n");
  vtkShaderProgram::Substitute(source, "//VolumeCut::ThinBone::Dec",
    features.ThinBone ? vtkVolumeCutThinBoneFS
                      : "const int thinBone = 0;\n"
                        "void applyThinBone(int object, vec3 index, vec3 normal, inout vec3 rgb, inout float alpha) {}\n");
  vtkShaderProgram::Substitute(source, "//VolumeCut::Shading::Dec", vtkVolumeCutShadingFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::PieceClassification::Dec", vtkVolumeCutPieceClassificationFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::Composite::Dec",
    (features.Composite ? std::string(vtkVolumeCutCompositeFS)
                        : std::string("bool compositeStep(inout Sample a, inout Sample b, inout int lastCutBorder) { return true; }\n")) +
      features.ExtraDeclarations);

  // The scene's switches become constants: the compiler drops the branches
  // of features not in use.
  const int fractions = std::min(std::max(features.Fractions, 0), 4);
  const int planes = std::min(std::max(features.ClipPlanes, 0), 6);
  const std::pair<const char*, int> constants[] = {
    { "hasLabels", features.LabelMap || fractions > 0 ? 1 : 0 },
    { "hasLabelMap", features.LabelMap ? 1 : 0 },
    { "fractionCount", fractions },
    { "blendMode", features.Composite ? 1 : 0 },
    { "thinBone", features.ThinBone ? 1 : 0 },
    { "ambientOcclusion", features.AmbientOcclusion ? 1 : 0 },
    { "planeCount", planes },
  };
  for (const auto& constant : constants)
  {
    const std::string name = constant.first;
    vtkShaderProgram::Substitute(source, "uniform int " + name + ";", "const int " + name + " = " + std::to_string(constant.second) + ";");
  }

  // One copy of the cut-field code per field, and the dispatch by index.
  std::string declarations;
  std::string calls;
  std::string init;
  std::string steps = "float cutStepOf(int n)\n{\n";
  for (int n = 0; n < cuts; ++n)
  {
    const std::string index = std::to_string(n);
    std::string field = vtkVolumeCutCutFieldFS;
    vtkShaderProgram::Substitute(field, "@N@", index);
    declarations += field;
    calls += "  if (n == " + index + ")\n  {\n    return cutDistance" + index + "(world);\n  }\n";
    init += "  cutDimensions" + index + " = ivec3(cutDimensionsF" + index + " + 0.5);\n";
    steps += "  if (n == " + index + ")\n  {\n    return cutStep" + index + ";\n  }\n";
  }
  steps += "  return 1.0;\n}\n";
  vtkShaderProgram::Substitute(source, "//VolumeCut::CutField::Dec", declarations + steps);
  vtkShaderProgram::Substitute(source, "//VolumeCut::CutField::Calls", calls);
  vtkShaderProgram::Substitute(source, "//VolumeCut::CutField::Init", init);
  return source;
}

//------------------------------------------------------------------------------
std::string vtkVolumeCutShaderComposer::Describe(const Features& features)
{
  std::string text = "cuts=" + std::to_string(features.CutFields);
  text += features.LabelMap ? " labels" : "";
  text += features.Fractions > 0 ? " fractions=" + std::to_string(features.Fractions) : "";
  text += features.Composite ? " composite" : " iso";
  text += features.ThinBone ? " thin-bone" : "";
  text += features.AmbientOcclusion ? " occlusion" : "";
  text += features.ClipPlanes > 0 ? " planes=" + std::to_string(features.ClipPlanes) : "";
  text += features.AnatomyUnorm16 ? " ct16" : "";
  const bool anyCut16 = std::find(features.CutAtlasUnorm16.begin(), features.CutAtlasUnorm16.end(), true) != features.CutAtlasUnorm16.end();
  text += anyCut16 ? " cut16" : "";
  text += features.AnatomyFiltered ? " ct-filtered" : "";
  text += features.FractionsFiltered ? " fractions-filtered" : "";
  text += features.FilterWeightBits > 0 ? " weights=" + std::to_string(features.FilterWeightBits) : "";
  return text;
}
