/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutToolDisplayNode.h"
#include "vtkMRMLVolumeCutToolNode.h"

// MRML includes
#include <vtkMRMLLinearTransformNode.h>
#include <vtkMRMLModelNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkBinaryLabelmapToClosedSurfaceConversionRule.h>
#include <vtkClosedSurfaceToBinaryLabelmapConversionRule.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverterFactory.h>

// vtkAddon includes
#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

// VTK includes
#include <vtkCallbackCommand.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkCubeSource.h>

// STD includes
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

// Slicer's build tree has the MRML testing macros. The slicer-core SDK lacks
// them and the template part of vtkMRMLCoreTestingUtilities.h, but MRMLCore
// exports the function behind the macro.
#if __has_include(<vtkMRMLCoreTestingMacros.h>)
#include <vtkMRMLCoreTestingMacros.h>
#else
namespace vtkMRMLCoreTestingUtilities
{
VTK_MRML_EXPORT int ExerciseAllBasicMRMLMethods(vtkMRMLNode* node);
}
#define EXERCISE_ALL_BASIC_MRML_METHODS(node) CHECK_EXIT_SUCCESS(vtkMRMLCoreTestingUtilities::ExerciseAllBasicMRMLMethods(node))
#endif

namespace
{
struct GeometryEventCounter
{
  int Count{ 0 };
  static void Callback(vtkObject*, unsigned long, void* clientData, void*) { ++static_cast<GeometryEventCounter*>(clientData)->Count; }
};

vtkMRMLScene* NewToolScene()
{
  vtkMRMLScene* scene = vtkMRMLScene::New();
  scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutNode>::New());
  scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutToolNode>::New());
  scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutToolDisplayNode>::New());
  return scene;
}

/// Each rejected value leaves the property as it was and logs exactly one error.
int CheckRejected(vtkMRMLVolumeCutToolNode* node, void (vtkMRMLVolumeCutToolNode::*setter)(double), double (vtkMRMLVolumeCutToolNode::*getter)(),
                  const std::vector<double>& values)
{
  for (double value : values)
  {
    const double before = (node->*getter)();
    TESTING_OUTPUT_RESET();
    (node->*setter)(value);
    TESTING_OUTPUT_ASSERT_ERRORS(1);
    TESTING_OUTPUT_RESET();
    CHECK_DOUBLE((node->*getter)(), before);
  }
  return EXIT_SUCCESS;
}

int TestBasicMethods()
{
  vtkSmartPointer<vtkMRMLScene> scene = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  vtkNew<vtkMRMLVolumeCutToolNode> tool;
  scene->AddNode(tool);
  EXERCISE_ALL_BASIC_MRML_METHODS(tool);
  vtkNew<vtkMRMLVolumeCutToolDisplayNode> display;
  scene->AddNode(display);
  EXERCISE_ALL_BASIC_MRML_METHODS(display);
  return EXIT_SUCCESS;
}

int TestDefaultsSetGetAndValidation()
{
  vtkNew<vtkMRMLVolumeCutToolNode> tool;
  CHECK_STD_STRING(tool->GetNodeTagName(), "VolumeCutTool");
  CHECK_BOOL(tool->GetUndoEnabled(), true);
  CHECK_INT(tool->GetShape(), vtkMRMLVolumeCutToolNode::Sphere);
  CHECK_INT(tool->GetBurrType(), vtkMRMLVolumeCutToolNode::Cutting);
  CHECK_DOUBLE(tool->GetDiameter(), 4.0);
  CHECK_DOUBLE(tool->GetPower(), 1.0);
  CHECK_BOOL(tool->GetUseCutNodeRoles(), true);
  CHECK_INT(static_cast<int>(tool->GetCuttableSegmentIDs().size()), 0);

  // Names of enumerated values, both ways; unknown names are -1.
  for (int shape = 0; shape < vtkMRMLVolumeCutToolNode::Shape_Last; ++shape)
  {
    CHECK_INT(vtkMRMLVolumeCutToolNode::GetShapeFromString(vtkMRMLVolumeCutToolNode::GetShapeAsString(shape)), shape);
  }
  CHECK_STRING(vtkMRMLVolumeCutToolNode::GetShapeAsString(vtkMRMLVolumeCutToolNode::DiskSaw), "DiskSaw");
  CHECK_STRING(vtkMRMLVolumeCutToolNode::GetBurrTypeAsString(vtkMRMLVolumeCutToolNode::Diamond), "Diamond");
  CHECK_INT(vtkMRMLVolumeCutToolNode::GetBurrTypeFromString("Cutting"), vtkMRMLVolumeCutToolNode::Cutting);
  CHECK_INT(vtkMRMLVolumeCutToolNode::GetShapeFromString("Hammer"), -1);
  CHECK_INT(vtkMRMLVolumeCutToolNode::GetShapeFromString(nullptr), -1);
  CHECK_INT(vtkMRMLVolumeCutToolNode::GetBurrTypeFromString("sphere"), -1);
  CHECK_NULL(vtkMRMLVolumeCutToolNode::GetShapeAsString(vtkMRMLVolumeCutToolNode::Shape_Last));

  // Set and get within range.
  tool->SetBurrType(vtkMRMLVolumeCutToolNode::Diamond);
  CHECK_INT(tool->GetBurrType(), vtkMRMLVolumeCutToolNode::Diamond);
  for (double diameter : { 1.0, 2.3, 7.0 })
  {
    tool->SetDiameter(diameter);
    CHECK_DOUBLE(tool->GetDiameter(), diameter);
  }
  tool->SetLength(12.5);
  tool->SetThickness(0.4);
  tool->SetWidth(9.0);
  tool->SetPower(0.35);
  tool->SetSpeed(80000.0);
  CHECK_DOUBLE(tool->GetLength(), 12.5);
  CHECK_DOUBLE(tool->GetThickness(), 0.4);
  CHECK_DOUBLE(tool->GetWidth(), 9.0);
  CHECK_DOUBLE(tool->GetPower(), 0.35);
  CHECK_DOUBLE(tool->GetSpeed(), 80000.0);
  tool->UseCutNodeRolesOff();
  CHECK_BOOL(tool->GetUseCutNodeRoles(), false);

  // Out of range, not a number: an error each, the value kept.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double infinity = std::numeric_limits<double>::infinity();
  CHECK_EXIT_SUCCESS(CheckRejected(tool, &vtkMRMLVolumeCutToolNode::SetDiameter, &vtkMRMLVolumeCutToolNode::GetDiameter, { 0.5, 7.01, 20.0, -3.0, nan, infinity }));
  CHECK_EXIT_SUCCESS(CheckRejected(tool, &vtkMRMLVolumeCutToolNode::SetLength, &vtkMRMLVolumeCutToolNode::GetLength, { 0.0, 100.5, nan }));
  CHECK_EXIT_SUCCESS(CheckRejected(tool, &vtkMRMLVolumeCutToolNode::SetThickness, &vtkMRMLVolumeCutToolNode::GetThickness, { 0.05, 5.5, -infinity }));
  CHECK_EXIT_SUCCESS(CheckRejected(tool, &vtkMRMLVolumeCutToolNode::SetWidth, &vtkMRMLVolumeCutToolNode::GetWidth, { 0.5, 51.0 }));
  CHECK_EXIT_SUCCESS(CheckRejected(tool, &vtkMRMLVolumeCutToolNode::SetPower, &vtkMRMLVolumeCutToolNode::GetPower, { -0.1, 1.5, nan }));
  CHECK_EXIT_SUCCESS(CheckRejected(tool, &vtkMRMLVolumeCutToolNode::SetSpeed, &vtkMRMLVolumeCutToolNode::GetSpeed, { -1.0, 200000.0, nan }));
  for (int invalid : { -1, static_cast<int>(vtkMRMLVolumeCutToolNode::Shape_Last), 42 })
  {
    TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
    tool->SetShape(invalid);
    TESTING_OUTPUT_ASSERT_ERRORS_END();
    CHECK_INT(tool->GetShape(), vtkMRMLVolumeCutToolNode::Sphere);
    TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
    tool->SetBurrType(invalid);
    TESTING_OUTPUT_ASSERT_ERRORS_END();
    CHECK_INT(tool->GetBurrType(), vtkMRMLVolumeCutToolNode::Diamond);
  }

  // A disk saw has its own diameter range; switching shapes keeps the diameter valid.
  tool->SetDiameter(2.0);
  tool->SetShape(vtkMRMLVolumeCutToolNode::DiskSaw);
  CHECK_DOUBLE(tool->GetDiameter(), vtkMRMLVolumeCutToolNode::GetMinimumDiameter(vtkMRMLVolumeCutToolNode::DiskSaw));
  tool->SetDiameter(25.0);
  CHECK_DOUBLE(tool->GetDiameter(), 25.0);
  tool->SetShape(vtkMRMLVolumeCutToolNode::Cylinder);
  CHECK_DOUBLE(tool->GetDiameter(), 7.0);
  CHECK_DOUBLE(vtkMRMLVolumeCutToolNode::GetMaximumDiameter(vtkMRMLVolumeCutToolNode::Sphere), 7.0);
  CHECK_DOUBLE(vtkMRMLVolumeCutToolNode::GetMinimumDiameter(vtkMRMLVolumeCutToolNode::Sphere), 1.0);

  // Radii follow the shape's geometry.
  tool->SetShape(vtkMRMLVolumeCutToolNode::Sphere);
  tool->SetDiameter(5.0);
  CHECK_DOUBLE(tool->GetCuttingRadius(), 2.5);
  CHECK_DOUBLE(tool->GetBoundingRadius(), 2.5);
  tool->SetShape(vtkMRMLVolumeCutToolNode::Cylinder);
  tool->SetDiameter(3.0);
  tool->SetLength(4.0);
  CHECK_DOUBLE(tool->GetCuttingRadius(), 1.5);
  CHECK_DOUBLE_TOLERANCE(tool->GetBoundingRadius(), std::sqrt(1.5 * 1.5 + 2.0 * 2.0), 1e-12);
  tool->SetShape(vtkMRMLVolumeCutToolNode::Blade);
  tool->SetWidth(10.0);
  tool->SetThickness(1.0);
  tool->SetLength(20.0);
  CHECK_DOUBLE(tool->GetCuttingRadius(), 5.0);
  CHECK_DOUBLE_TOLERANCE(tool->GetBoundingRadius(), 0.5 * std::sqrt(100.0 + 1.0 + 400.0), 1e-12);
  tool->SetShape(vtkMRMLVolumeCutToolNode::Mesh);
  CHECK_DOUBLE(tool->GetBoundingRadius(), 0.0);

  std::stringstream printed;
  tool->Print(printed);
  CHECK_BOOL(printed.str().find("Shape: Mesh") != std::string::npos, true);
  CHECK_BOOL(printed.str().find("BurrType: Diamond") != std::string::npos, true);
  return EXIT_SUCCESS;
}

int TestGeometryEvents()
{
  vtkSmartPointer<vtkMRMLScene> scene = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  vtkMRMLVolumeCutToolNode* tool = vtkMRMLVolumeCutToolNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutToolNode", "Burr"));
  GeometryEventCounter counter;
  vtkNew<vtkCallbackCommand> callback;
  callback->SetClientData(&counter);
  callback->SetCallback(GeometryEventCounter::Callback);
  tool->AddObserver(vtkMRMLVolumeCutToolNode::ToolGeometryModifiedEvent, callback);

  tool->SetDiameter(2.0);
  CHECK_INT(counter.Count, 1);
  tool->SetDiameter(2.0); // unchanged: no event
  tool->SetPower(0.5);
  tool->SetSpeed(30000.0);
  tool->SetBurrType(vtkMRMLVolumeCutToolNode::Diamond);
  CHECK_INT(counter.Count, 1);
  tool->SetShape(vtkMRMLVolumeCutToolNode::Mesh);
  CHECK_INT(counter.Count, 2);

  vtkNew<vtkCubeSource> cube;
  cube->SetCenter(1.0, 0.0, 0.0);
  cube->SetXLength(2.0);
  cube->SetYLength(2.0);
  cube->SetZLength(2.0);
  cube->Update();
  vtkMRMLModelNode* mesh = vtkMRMLModelNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLModelNode", "ToolMesh"));
  tool->SetAndObserveMeshModelNodeID(mesh->GetID());
  CHECK_POINTER(tool->GetMeshModelNode(), mesh);
  CHECK_INT(counter.Count, 3);
  mesh->SetAndObservePolyData(cube->GetOutput());
  CHECK_BOOL(counter.Count >= 4, true);
  CHECK_DOUBLE_TOLERANCE(tool->GetBoundingRadius(), std::sqrt(6.0), 1e-6); // corner (2, 1, 1)
  const int beforeRemoval = counter.Count;
  scene->RemoveNode(mesh);
  CHECK_NULL(tool->GetMeshModelNode());
  CHECK_BOOL(counter.Count > beforeRemoval, true);
  return EXIT_SUCCESS;
}

int TestSensibility()
{
  vtkSmartPointer<vtkMRMLScene> scene = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  vtkMRMLSegmentationNode* segmentation = vtkMRMLSegmentationNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLSegmentationNode", "Anatomy"));
  for (const char* name : { "Bone", "FacialNerve", "Sinus", "Dura" })
  {
    vtkNew<vtkSegment> segment;
    segment->SetName(name);
    segmentation->GetSegmentation()->AddSegment(segment, name);
  }
  vtkMRMLVolumeCutNode* cut = vtkMRMLVolumeCutNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutNode", "Cut"));
  cut->SetAndObserveSegmentationNodeID(segmentation->GetID());
  cut->SetSegmentCuttable("Bone", true);
  cut->SetSegmentProtected("FacialNerve", true);
  vtkMRMLVolumeCutToolNode* tool = vtkMRMLVolumeCutToolNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutToolNode", "Burr"));

  // Following the cut node's roles.
  CHECK_BOOL(tool->MayCutSegment(cut, "Bone"), true);
  CHECK_BOOL(tool->MayCutSegment(cut, "FacialNerve"), false);
  CHECK_BOOL(tool->MayCutSegment(cut, "Sinus"), false);
  CHECK_BOOL(tool->MayCutSegment(nullptr, "Bone"), false);
  CHECK_BOOL(tool->GetEffectiveCuttableSegmentIDs(cut) == std::vector<std::string>({ "Bone" }), true);

  // Its own list: the sinus (no role) becomes the tool's, the nerve stays protected.
  tool->SetCuttableSegmentIDs({ "Sinus", "FacialNerve", "", "Sinus", "Removed" });
  CHECK_BOOL(tool->GetCuttableSegmentIDs() == std::vector<std::string>({ "Sinus", "FacialNerve", "Removed" }), true);
  CHECK_BOOL(tool->MayCutSegment(cut, "Sinus"), false); // still following the roles
  tool->SetUseCutNodeRoles(false);
  CHECK_BOOL(tool->MayCutSegment(cut, "Sinus"), true);
  CHECK_BOOL(tool->MayCutSegment(cut, "Bone"), false);
  CHECK_BOOL(tool->MayCutSegment(cut, "FacialNerve"), false);
  CHECK_BOOL(tool->IsSegmentInCuttableList("FacialNerve"), true);
  CHECK_BOOL(tool->MayCutSegment(nullptr, "FacialNerve"), true);
  // Segments the segmentation lacks are not reported as cuttable.
  CHECK_BOOL(tool->GetEffectiveCuttableSegmentIDs(cut) == std::vector<std::string>({ "Sinus" }), true);
  tool->SetSegmentCuttable("Dura", true);
  tool->SetSegmentCuttable("Sinus", false);
  CHECK_BOOL(tool->GetEffectiveCuttableSegmentIDs(cut) == std::vector<std::string>({ "Dura" }), true);
  // Protecting a segment later takes it from the tool too.
  cut->SetSegmentProtected("Dura", true);
  CHECK_BOOL(tool->MayCutSegment(cut, "Dura"), false);
  CHECK_INT(static_cast<int>(tool->GetEffectiveCuttableSegmentIDs(cut).size()), 0);
  return EXIT_SUCCESS;
}

vtkMRMLVolumeCutToolNode* AddConfiguredTool(vtkMRMLScene* scene)
{
  vtkMRMLLinearTransformNode* pose = vtkMRMLLinearTransformNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLLinearTransformNode", "BurrPose"));
  vtkNew<vtkMatrix4x4> matrix;
  matrix->SetElement(0, 3, 12.5);
  matrix->SetElement(1, 3, -3.25);
  matrix->SetElement(2, 3, 40.0);
  pose->SetMatrixTransformToParent(matrix);
  vtkMRMLModelNode* mesh = vtkMRMLModelNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLModelNode", "ToolMesh"));
  vtkMRMLVolumeCutToolNode* tool = vtkMRMLVolumeCutToolNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutToolNode", "Saw"));
  tool->SetShape(vtkMRMLVolumeCutToolNode::DiskSaw);
  tool->SetBurrType(vtkMRMLVolumeCutToolNode::Diamond);
  tool->SetDiameter(22.5);
  tool->SetLength(3.5);
  tool->SetThickness(0.6);
  tool->SetWidth(12.0);
  tool->SetPower(0.45);
  tool->SetSpeed(12000.0);
  tool->SetUseCutNodeRoles(false);
  tool->SetCuttableSegmentIDs({ "Bone", "Lamina" });
  tool->SetAndObserveMeshModelNodeID(mesh->GetID());
  tool->SetAndObserveTransformNodeID(pose->GetID());
  tool->CreateDefaultDisplayNodes();
  vtkMRMLVolumeCutToolDisplayNode* display = tool->GetVolumeCutToolDisplayNode();
  display->SetShowAxis(false);
  display->SetGlyphOpacityWhileCutting(0.55);
  display->SetColor(0.9, 0.1, 0.2);
  return tool;
}

int CheckConfiguredTool(vtkMRMLVolumeCutToolNode* tool)
{
  CHECK_NOT_NULL(tool);
  CHECK_STD_STRING(tool->GetName(), "Saw");
  CHECK_INT(tool->GetShape(), vtkMRMLVolumeCutToolNode::DiskSaw);
  CHECK_INT(tool->GetBurrType(), vtkMRMLVolumeCutToolNode::Diamond);
  CHECK_DOUBLE(tool->GetDiameter(), 22.5);
  CHECK_DOUBLE(tool->GetLength(), 3.5);
  CHECK_DOUBLE(tool->GetThickness(), 0.6);
  CHECK_DOUBLE(tool->GetWidth(), 12.0);
  CHECK_DOUBLE(tool->GetPower(), 0.45);
  CHECK_DOUBLE(tool->GetSpeed(), 12000.0);
  CHECK_BOOL(tool->GetUseCutNodeRoles(), false);
  CHECK_BOOL(tool->GetCuttableSegmentIDs() == std::vector<std::string>({ "Bone", "Lamina" }), true);
  CHECK_NOT_NULL(tool->GetMeshModelNode());
  CHECK_STD_STRING(tool->GetMeshModelNode()->GetName(), "ToolMesh");
  vtkMRMLTransformNode* pose = tool->GetParentTransformNode();
  CHECK_NOT_NULL(pose);
  CHECK_STD_STRING(pose->GetName(), "BurrPose");
  vtkNew<vtkMatrix4x4> matrix;
  pose->GetMatrixTransformToParent(matrix);
  CHECK_DOUBLE(matrix->GetElement(0, 3), 12.5);
  CHECK_DOUBLE(matrix->GetElement(1, 3), -3.25);
  CHECK_DOUBLE(matrix->GetElement(2, 3), 40.0);
  vtkMRMLVolumeCutToolDisplayNode* display = tool->GetVolumeCutToolDisplayNode();
  CHECK_NOT_NULL(display);
  CHECK_BOOL(display->GetShowAxis(), false);
  CHECK_DOUBLE(display->GetGlyphOpacityWhileCutting(), 0.55);
  CHECK_DOUBLE(display->GetColor()[0], 0.9);
  return EXIT_SUCCESS;
}

int TestSceneRoundTripAndCopy(const std::string& temporaryDir)
{
  vtkSmartPointer<vtkMRMLScene> scene = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  vtkMRMLVolumeCutToolNode* tool = AddConfiguredTool(scene);
  CHECK_EXIT_SUCCESS(CheckConfiguredTool(tool));

  scene->SetSaveToXMLString(1);
  scene->Commit();
  const std::string xml = scene->GetSceneXMLString();
  CHECK_BOOL(xml.find("shape=\"DiskSaw\"") != std::string::npos, true);
  CHECK_BOOL(xml.find("burrType=\"Diamond\"") != std::string::npos, true);
  CHECK_BOOL(xml.find("cuttableSegmentIDs=\"Bone;Lamina\"") != std::string::npos, true);

  vtkSmartPointer<vtkMRMLScene> reloaded = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  reloaded->SetLoadFromXMLString(1);
  reloaded->SetSceneXMLString(xml);
  reloaded->Import();
  CHECK_EXIT_SUCCESS(CheckConfiguredTool(vtkMRMLVolumeCutToolNode::SafeDownCast(reloaded->GetFirstNodeByClass("vtkMRMLVolumeCutToolNode"))));

  // A .mrml file on disk, as Slicer's "Load scene" reads it.
  const std::string sceneFile = temporaryDir + "/vtkMRMLVolumeCutToolNodeTest1.mrml";
  scene->SetSaveToXMLString(0);
  scene->SetURL(sceneFile.c_str());
  CHECK_BOOL(scene->Commit() != 0, true);
  vtkSmartPointer<vtkMRMLScene> fromFile = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  fromFile->SetURL(sceneFile.c_str());
  fromFile->Import();
  CHECK_EXIT_SUCCESS(CheckConfiguredTool(vtkMRMLVolumeCutToolNode::SafeDownCast(fromFile->GetFirstNodeByClass("vtkMRMLVolumeCutToolNode"))));

  vtkNew<vtkMRMLVolumeCutToolNode> copy;
  copy->CopyContent(tool);
  CHECK_INT(copy->GetShape(), vtkMRMLVolumeCutToolNode::DiskSaw);
  CHECK_DOUBLE(copy->GetDiameter(), 22.5);
  CHECK_BOOL(copy->GetCuttableSegmentIDs() == tool->GetCuttableSegmentIDs(), true);
  return EXIT_SUCCESS;
}

int TestUndo()
{
  vtkSmartPointer<vtkMRMLScene> scene = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  vtkMRMLVolumeCutToolNode* tool = AddConfiguredTool(scene);
  scene->SetUndoOn();
  scene->SaveStateForUndo();
  tool->SetShape(vtkMRMLVolumeCutToolNode::Sphere);
  tool->SetDiameter(2.0);
  tool->SetPower(0.9);
  tool->SetUseCutNodeRoles(true);
  tool->SetCuttableSegmentIDs({});
  tool->GetVolumeCutToolDisplayNode()->SetShowAxis(true);
  CHECK_DOUBLE(tool->GetDiameter(), 2.0);

  scene->Undo();
  CHECK_EXIT_SUCCESS(CheckConfiguredTool(vtkMRMLVolumeCutToolNode::SafeDownCast(scene->GetFirstNodeByClass("vtkMRMLVolumeCutToolNode"))));
  scene->Redo();
  tool = vtkMRMLVolumeCutToolNode::SafeDownCast(scene->GetFirstNodeByClass("vtkMRMLVolumeCutToolNode"));
  CHECK_INT(tool->GetShape(), vtkMRMLVolumeCutToolNode::Sphere);
  CHECK_DOUBLE(tool->GetDiameter(), 2.0);
  CHECK_DOUBLE(tool->GetPower(), 0.9);
  CHECK_BOOL(tool->GetUseCutNodeRoles(), true);
  CHECK_BOOL(tool->GetVolumeCutToolDisplayNode()->GetShowAxis(), true);
  return EXIT_SUCCESS;
}

int ImportOneTool(const std::string& attributes, int expectedErrors, vtkSmartPointer<vtkMRMLScene>& scene, vtkMRMLVolumeCutToolNode*& tool)
{
  const std::string xml = "<MRML version=\"Slicer4.4.0\"><VolumeCutTool id=\"vtkMRMLVolumeCutToolNode1\" name=\"Tool\" " + attributes + "></VolumeCutTool></MRML>";
  scene = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  scene->SetLoadFromXMLString(1);
  scene->SetSceneXMLString(xml);
  TESTING_OUTPUT_RESET();
  scene->Import();
  TESTING_OUTPUT_ASSERT_ERRORS(expectedErrors);
  TESTING_OUTPUT_RESET();
  tool = vtkMRMLVolumeCutToolNode::SafeDownCast(scene->GetFirstNodeByClass("vtkMRMLVolumeCutToolNode"));
  CHECK_NOT_NULL(tool);
  return EXIT_SUCCESS;
}

int TestCorruptXML()
{
  vtkSmartPointer<vtkMRMLScene> scene;
  vtkMRMLVolumeCutToolNode* tool = nullptr;
  // Each bad value: one error, the default kept, the rest read.
  CHECK_EXIT_SUCCESS(ImportOneTool("shape=\"Hammer\" burrType=\"Ceramic\" diameter=\"abc\" power=\"2\" speed=\"-5\" length=\"9\"", 5, scene, tool));
  CHECK_INT(tool->GetShape(), vtkMRMLVolumeCutToolNode::Sphere);
  CHECK_INT(tool->GetBurrType(), vtkMRMLVolumeCutToolNode::Cutting);
  CHECK_DOUBLE(tool->GetDiameter(), 4.0);
  CHECK_DOUBLE(tool->GetPower(), 1.0);
  CHECK_DOUBLE(tool->GetSpeed(), 60000.0);
  CHECK_DOUBLE(tool->GetLength(), 9.0);

  // A hand-edited file with the diameter before the shape is read as meant.
  CHECK_EXIT_SUCCESS(ImportOneTool("diameter=\"30\" shape=\"DiskSaw\"", 0, scene, tool));
  CHECK_INT(tool->GetShape(), vtkMRMLVolumeCutToolNode::DiskSaw);
  CHECK_DOUBLE(tool->GetDiameter(), 30.0);

  // A burr of 30 mm does not exist: refused.
  CHECK_EXIT_SUCCESS(ImportOneTool("shape=\"Sphere\" diameter=\"30\"", 1, scene, tool));
  CHECK_DOUBLE(tool->GetDiameter(), 4.0);
  return EXIT_SUCCESS;
}

int TestDisplayNode()
{
  vtkNew<vtkMRMLVolumeCutToolDisplayNode> display;
  CHECK_STD_STRING(display->GetNodeTagName(), "VolumeCutToolDisplay");
  CHECK_BOOL(display->GetShowAxis(), true);
  CHECK_DOUBLE(display->GetGlyphOpacityWhileCutting(), 0.3);
  display->SetGlyphOpacityWhileCutting(1.5);
  CHECK_DOUBLE(display->GetGlyphOpacityWhileCutting(), 1.0);

  // Without a scene, or without the display class registered, no display node.
  vtkNew<vtkMRMLVolumeCutToolNode> orphan;
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  orphan->CreateDefaultDisplayNodes();
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_NULL(orphan->GetDisplayNode());
  vtkNew<vtkMRMLScene> bareScene;
  bareScene->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutToolNode>::New());
  vtkMRMLVolumeCutToolNode* tool = vtkMRMLVolumeCutToolNode::SafeDownCast(bareScene->AddNewNodeByClass("vtkMRMLVolumeCutToolNode"));
  TESTING_OUTPUT_RESET();
  tool->CreateDefaultDisplayNodes();
  CHECK_BOOL(vtkTestingOutputWindow::GetInstance()->GetNumberOfLoggedErrorMessages() > 0, true);
  TESTING_OUTPUT_RESET();
  CHECK_NULL(tool->GetDisplayNode());

  // Creating twice gives one display node.
  vtkSmartPointer<vtkMRMLScene> scene = vtkSmartPointer<vtkMRMLScene>::Take(NewToolScene());
  tool = vtkMRMLVolumeCutToolNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutToolNode"));
  tool->CreateDefaultDisplayNodes();
  tool->CreateDefaultDisplayNodes();
  CHECK_INT(tool->GetNumberOfDisplayNodes(), 1);
  CHECK_NOT_NULL(tool->GetVolumeCutToolDisplayNode());
  CHECK_INT(scene->GetNumberOfNodesByClass("vtkMRMLVolumeCutToolDisplayNode"), 1);
  return EXIT_SUCCESS;
}
} // namespace

int vtkMRMLVolumeCutToolNodeTest1(int argc, char* argv[])
{
  // As the Segmentations module does at start-up: segments need the
  // representations these rules provide.
  vtkSegmentationConverterFactory::GetInstance()->RegisterConverterRule(vtkSmartPointer<vtkBinaryLabelmapToClosedSurfaceConversionRule>::New());
  vtkSegmentationConverterFactory::GetInstance()->RegisterConverterRule(vtkSmartPointer<vtkClosedSurfaceToBinaryLabelmapConversionRule>::New());
  const std::string temporaryDir = argc > 1 ? argv[argc - 1] : ".";
  CHECK_EXIT_SUCCESS(TestBasicMethods());
  CHECK_EXIT_SUCCESS(TestDefaultsSetGetAndValidation());
  CHECK_EXIT_SUCCESS(TestGeometryEvents());
  CHECK_EXIT_SUCCESS(TestSensibility());
  CHECK_EXIT_SUCCESS(TestSceneRoundTripAndCopy(temporaryDir));
  CHECK_EXIT_SUCCESS(TestUndo());
  CHECK_EXIT_SUCCESS(TestCorruptXML());
  CHECK_EXIT_SUCCESS(TestDisplayNode());
  return EXIT_SUCCESS;
}
