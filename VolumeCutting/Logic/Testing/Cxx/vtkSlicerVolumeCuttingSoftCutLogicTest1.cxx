/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkSlicerVolumeCuttingLogic.h"
#include "vtkSlicerVolumeCuttingSoftCutLogic.h"
#include "vtkVolumeCutField.h"
#include "vtkVolumeCutResectionPlanner.h"

// MRML includes
#include <vtkMRMLMarkupsClosedCurveNode.h>
#include <vtkMRMLMarkupsCurveNode.h>
#include <vtkMRMLModelNode.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLTableNode.h>

// vtkAddon includes
#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

// VTK includes
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>
#include <vtkVector.h>

// STD includes
#include <cmath>
#include <fstream>
#include <string>

namespace
{
// A flat face: air above the skin plane S = 12 mm, soft tissue down to a
// bone plate at S = 2 mm, bone below; on a grid turned 20 degrees about S
// with 1 x 1 x 1.25 mm voxels. A circle on the skin with the average normal
// resects a cylinder: pi r^2 d exactly.
const double SkinS = 12.0;
const double BoneS = 2.0;
const double Pi = 3.14159265358979323846;

vtkMRMLScalarVolumeNode* AddFlatFace(vtkMRMLScene* scene)
{
  const int dims[3] = { 64, 64, 40 };
  vtkNew<vtkMatrix4x4> ijkToRas;
  const double c = std::cos(Pi / 9.0);
  const double s = std::sin(Pi / 9.0);
  const double spacing[3] = { 1.0, 1.0, 1.25 };
  const double axes[3][3] = { { c, s, 0 }, { -s, c, 0 }, { 0, 0, 1 } };
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      ijkToRas->SetElement(row, column, axes[column][row] * spacing[column]);
    }
  }
  // The grid's centre at RAS (0, 0, 0).
  for (int row = 0; row < 3; ++row)
  {
    double center = 0.0;
    for (int column = 0; column < 3; ++column)
    {
      center += ijkToRas->GetElement(row, column) * (dims[column] - 1) / 2.0;
    }
    ijkToRas->SetElement(row, 3, -center);
  }
  vtkNew<vtkImageData> image;
  image->SetDimensions(dims[0], dims[1], dims[2]);
  image->AllocateScalars(VTK_SHORT, 1);
  for (int k = 0; k < dims[2]; ++k)
  {
    for (int j = 0; j < dims[1]; ++j)
    {
      for (int i = 0; i < dims[0]; ++i)
      {
        const double ijk[4] = { double(i), double(j), double(k), 1.0 };
        double ras[4];
        ijkToRas->MultiplyPoint(ijk, ras);
        const double tissue = 0.5 * (1.0 + std::tanh((SkinS - ras[2]) / 0.75));
        const double bone = 0.5 * (1.0 + std::tanh((BoneS - ras[2]) / 0.75));
        image->SetScalarComponentFromDouble(i, j, k, 0, -1000.0 + 1040.0 * tissue + 1160.0 * bone);
      }
    }
  }
  vtkMRMLScalarVolumeNode* volume = vtkMRMLScalarVolumeNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLScalarVolumeNode", "FlatFace"));
  volume->SetAndObserveImageData(image);
  volume->SetIJKToRASMatrix(ijkToRas);
  return volume;
}

template <typename Curve>
Curve* AddCircle(vtkMRMLScene* scene, const char* className, double radius, int count)
{
  Curve* curve = Curve::SafeDownCast(scene->AddNewNodeByClass(className, "Outline"));
  for (int n = 0; n < count; ++n)
  {
    const double a = 2.0 * Pi * n / count;
    curve->AddControlPointWorld(vtkVector3d(radius * std::cos(a) + 2.0, radius * std::sin(a) - 3.0, SkinS));
  }
  return curve;
}

double TableValue(vtkMRMLTableNode* table, const std::string& measurement)
{
  vtkTable* content = table->GetTable();
  for (vtkIdType row = 0; row < content->GetNumberOfRows(); ++row)
  {
    if (content->GetValueByName(row, "Measurement").ToString() == measurement)
    {
      return content->GetValueByName(row, "Value").ToDouble();
    }
  }
  return -1.0;
}
} // namespace

int vtkSlicerVolumeCuttingSoftCutLogicTest1(int argc, char* argv[])
{
  const std::string temporary = argc > 1 ? argv[argc - 1] : ".";
  vtkNew<vtkMRMLScene> scene;
  vtkNew<vtkSlicerVolumeCuttingLogic> module;
  module->SetMRMLScene(scene);
  vtkNew<vtkSlicerVolumeCuttingSoftCutLogic> logic;
  logic->SetMRMLScene(scene);
  logic->SetVolumeCuttingLogic(module);
  logic->SetNormalMode(vtkVolumeCutResectionPlanner::AverageNormal);
  logic->SetMaximumDepth(15.0);
  // The skin and the bone plate where the CT is half-way between their tissues.
  logic->SetSkinIsoValue(-480.0);
  logic->SetSoftTissueRange(-480.0, 620.0);
  CHECK_POINTER(logic->GetVolumeCuttingLogic(), module.GetPointer());

  vtkMRMLScalarVolumeNode* volume = AddFlatFace(scene);
  vtkMRMLVolumeCutNode* cut = module->AddVolumeCutNode(volume, nullptr);
  const double radius = 10.0;
  vtkMRMLMarkupsClosedCurveNode* outline = AddCircle<vtkMRMLMarkupsClosedCurveNode>(scene, "vtkMRMLMarkupsClosedCurveNode", radius, 16);
  CHECK_BOOL(logic->PlanResection(cut, outline), true);
  CHECK_NOT_NULL(logic->GetPlanner(cut));

  // Measured: a cylinder of the outline's radius and the depth of cut.
  for (double depth : { 4.0, 7.0 })
  {
    vtkMRMLTableNode* table = logic->MeasureResection(cut, depth);
    CHECK_NOT_NULL(table);
    CHECK_POINTER(vtkMRMLTableNode::SafeDownCast(cut->GetNodeReference(vtkSlicerVolumeCuttingSoftCutLogic::GetResectionTableReferenceRole())), table);
    const double exact = Pi * radius * radius * depth;
    CHECK_DOUBLE_TOLERANCE(TableValue(table, "Resected volume"), exact, 0.02 * exact);
    CHECK_DOUBLE_TOLERANCE(TableValue(table, "Thickness"), depth, 0.5);
    CHECK_DOUBLE_TOLERANCE(TableValue(table, "Thickness axis S"), 1.0, 1e-3);
    CHECK_DOUBLE_TOLERANCE(TableValue(table, "Depth of cut"), depth, 1e-12);
  }
  // Down to the bone (10 mm of soft tissue): it stops there.
  vtkMRMLTableNode* deep = logic->MeasureResection(cut, 14.0);
  CHECK_DOUBLE_TOLERANCE(TableValue(deep, "Resected volume"), Pi * radius * radius * (SkinS - BoneS), 0.03 * Pi * radius * radius * (SkinS - BoneS));

  // The preview is a second removed region of the node, not a cut.
  CHECK_BOOL(logic->PreviewDepth(cut, 5.0), true);
  CHECK_NOT_NULL(cut->GetPreviewCutField());
  CHECK_BOOL(cut->GetPreviewCutField()->ComputeRemovedVolume() > 0.0, true);
  CHECK_DOUBLE_TOLERANCE(module->GetRemovedVolume(cut), 0.0, 1e-12);
  CHECK_BOOL(logic->PreviewDepth(cut, 6.0), true);
  // The carve: one undo step, the preview gone.
  CHECK_BOOL(logic->CarveResection(cut, 5.0), true);
  CHECK_NULL(cut->GetPreviewCutField());
  CHECK_INT(module->GetCutField(cut)->GetNumberOfUndoSteps(), 1);
  const double removed = module->GetRemovedVolume(cut);
  CHECK_BOOL(removed > Pi * radius * radius * 5.0, true); // the tissue and the air just above the skin
  CHECK_BOOL(module->UndoStroke(cut), true);
  CHECK_DOUBLE_TOLERANCE(module->GetRemovedVolume(cut), 0.0, 1e-9);
  CHECK_BOOL(module->RedoStroke(cut), true);
  CHECK_DOUBLE_TOLERANCE(module->GetRemovedVolume(cut), removed, 1e-6 * removed);

  // Exports.
  vtkMRMLModelNode* model = logic->CreateResectionModel(cut, 5.0, "Guide");
  CHECK_NOT_NULL(model);
  CHECK_BOOL(model->GetPolyData()->GetNumberOfPolys() > 100, true);
  const std::string stl = temporary + "/vtkSlicerVolumeCuttingSoftCutLogicTest1.stl";
  CHECK_BOOL(logic->ExportResectionToSTL(cut, 5.0, stl.c_str()), true);
  std::ifstream written(stl, std::ios::binary | std::ios::ate);
  CHECK_BOOL(written.good() && written.tellg() > 1000, true);

  // Bad input: refused with a message, nothing changed.
  vtkMRMLMarkupsCurveNode* open = AddCircle<vtkMRMLMarkupsCurveNode>(scene, "vtkMRMLMarkupsCurveNode", radius, 16);
  vtkVolumeCutResectionPlanner* planner = logic->GetPlanner(cut);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(logic->PlanResection(cut, open), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(std::string(logic->GetErrorMessage()).find("open curve") != std::string::npos, true);
  vtkMRMLMarkupsClosedCurveNode* two = AddCircle<vtkMRMLMarkupsClosedCurveNode>(scene, "vtkMRMLMarkupsClosedCurveNode", radius, 2);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(logic->PlanResection(cut, two), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(std::string(logic->GetErrorMessage()).find("at least 3") != std::string::npos, true);
  outline->SetNthControlPointPositionWorld(3, 1.0, 2.0, SkinS + 8.0);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(logic->PlanResection(cut, outline), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(std::string(logic->GetErrorMessage()).find("control point 4") != std::string::npos, true);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(logic->CarveResection(cut, 0.0), false);
  CHECK_BOOL(logic->CarveResection(cut, 16.0), false);
  CHECK_BOOL(logic->ExportResectionToSTL(cut, 5.0, (temporary + "/guide.ply").c_str()), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_POINTER(logic->GetPlanner(cut), planner);
  CHECK_DOUBLE_TOLERANCE(module->GetRemovedVolume(cut), removed, 1e-6 * removed);
  CHECK_INT(module->GetCutField(cut)->GetNumberOfUndoSteps(), 1);

  // A removed cut node takes its plan with it.
  vtkSmartPointer<vtkMRMLVolumeCutNode> kept = cut;
  scene->RemoveNode(cut);
  CHECK_NULL(logic->GetPlanner(cut));
  return EXIT_SUCCESS;
}
