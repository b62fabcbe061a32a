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

//------------------------------------------------------------------------------
std::string vtkVolumeCutShaderComposer::FragmentShader(const Features& features)
{
  const int cuts = std::max(features.CutFields, 0);
  std::string source = vtkVolumeCutRayCastFS;
  const std::string defines =
    "#define NUMBER_OF_CUTS " + std::to_string(cuts) + "\n#define CUT_SLOTS " + std::to_string(std::max(cuts, 1)) + "\n";
  vtkShaderProgram::Substitute(source, "//VTK::Output::Dec", "//VTK::Output::Dec\n" + defines);
  vtkShaderProgram::Substitute(source, "//VolumeCut::Classification::Dec", vtkVolumeCutClassificationFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::CutFields::Dec", vtkVolumeCutCutFieldsFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::EmptySpace::Dec", vtkVolumeCutEmptySpaceFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::BorderLocation::Dec", vtkVolumeCutBorderLocationFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::AmbientOcclusion::Dec", vtkVolumeCutAmbientOcclusionFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::ThinBone::Dec", vtkVolumeCutThinBoneFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::Shading::Dec", vtkVolumeCutShadingFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::PieceClassification::Dec", vtkVolumeCutPieceClassificationFS);
  vtkShaderProgram::Substitute(source, "//VolumeCut::Composite::Dec", vtkVolumeCutCompositeFS);

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
