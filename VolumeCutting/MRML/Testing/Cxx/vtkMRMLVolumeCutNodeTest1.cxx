/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"

// MRML includes
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkBinaryLabelmapToClosedSurfaceConversionRule.h>
#include <vtkClosedSurfaceToBinaryLabelmapConversionRule.h>
#include <vtkSegment.h>
#include <vtkSegmentationConverterFactory.h>
#include <vtkSegmentation.h>

// vtkAddon includes
#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

// VTK includes
#include <vtkCallbackCommand.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtksys/SystemTools.hxx>

// STD includes
#include <sstream>
#include <string>
#include <vector>

namespace
{
struct EventCounter
{
  int InputDataModified{ 0 };
  int SegmentRolesModified{ 0 };
  static void Callback(vtkObject*, unsigned long event, void* clientData, void*)
  {
    EventCounter* self = static_cast<EventCounter*>(clientData);
    if (event == vtkMRMLVolumeCutNode::InputDataModifiedEvent)
    {
      ++self->InputDataModified;
    }
    else if (event == vtkMRMLVolumeCutNode::SegmentRolesModifiedEvent)
    {
      ++self->SegmentRolesModified;
    }
  }
};

vtkMRMLScalarVolumeNode* AddVolume(vtkMRMLScene* scene)
{
  vtkMRMLScalarVolumeNode* volume = vtkMRMLScalarVolumeNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLScalarVolumeNode", "CT"));
  vtkNew<vtkImageData> image;
  image->SetDimensions(4, 4, 4);
  image->AllocateScalars(VTK_SHORT, 1);
  volume->SetAndObserveImageData(image);
  return volume;
}

vtkMRMLSegmentationNode* AddSegmentation(vtkMRMLScene* scene)
{
  vtkMRMLSegmentationNode* segmentation = vtkMRMLSegmentationNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLSegmentationNode", "Anatomy"));
  for (const char* name : { "Bone", "FacialNerve", "Sinus" })
  {
    vtkNew<vtkSegment> segment;
    segment->SetName(name);
    segmentation->GetSegmentation()->AddSegment(segment, name);
  }
  return segmentation;
}

int TestDefaultsAndValidation()
{
  vtkNew<vtkMRMLVolumeCutNode> node;
  CHECK_INT(node->GetSubVoxelFactor(), 2);
  CHECK_BOOL(node->GetUndoEnabled(), true);
  CHECK_STD_STRING(node->GetNodeTagName(), "VolumeCut");

  node->SetSubVoxelFactor(4);
  CHECK_INT(node->GetSubVoxelFactor(), 4);
  for (int invalid : { 0, 3, -2, 8 })
  {
    TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
    node->SetSubVoxelFactor(invalid);
    TESTING_OUTPUT_ASSERT_ERRORS_END();
    CHECK_INT(node->GetSubVoxelFactor(), 4);
  }

  // Without a segmentation there is nothing to give a role to.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(node->SetSegmentCuttable("Bone", true), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_INT(static_cast<int>(node->GetCuttableSegmentIDs().size()), 0);

  std::stringstream printed;
  node->Print(printed);
  CHECK_BOOL(printed.str().find("SubVoxelFactor: 4") != std::string::npos, true);
  return EXIT_SUCCESS;
}

int TestReferencesAndRoles()
{
  vtkNew<vtkMRMLScene> scene;
  scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutNode>::New());
  vtkMRMLScalarVolumeNode* volume = AddVolume(scene);
  vtkMRMLSegmentationNode* segmentation = AddSegmentation(scene);
  vtkMRMLVolumeCutNode* node = vtkMRMLVolumeCutNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutNode", "Cut"));
  CHECK_NOT_NULL(node);

  EventCounter counter;
  vtkNew<vtkCallbackCommand> callback;
  callback->SetClientData(&counter);
  callback->SetCallback(EventCounter::Callback);
  node->AddObserver(vtkMRMLVolumeCutNode::InputDataModifiedEvent, callback);
  node->AddObserver(vtkMRMLVolumeCutNode::SegmentRolesModifiedEvent, callback);

  node->SetAndObserveAnatomyVolumeNodeID(volume->GetID());
  node->SetAndObserveSegmentationNodeID(segmentation->GetID());
  CHECK_POINTER(node->GetAnatomyVolumeNode(), volume);
  CHECK_POINTER(node->GetSegmentationNode(), segmentation);
  CHECK_NULL(node->GetActiveToolNode());

  CHECK_BOOL(node->SetSegmentCuttable("Bone", true), true);
  CHECK_BOOL(node->SetSegmentProtected("FacialNerve", true), true);
  CHECK_BOOL(node->IsSegmentCuttable("Bone"), true);
  CHECK_BOOL(node->IsSegmentProtected("FacialNerve"), true);
  CHECK_BOOL(node->IsSegmentCuttable("FacialNerve"), false);
  CHECK_INT(counter.SegmentRolesModified, 2);

  // One role per segment: protecting a cuttable segment takes the cut role away.
  CHECK_BOOL(node->SetSegmentProtected("Bone", true), true);
  CHECK_BOOL(node->IsSegmentCuttable("Bone"), false);
  CHECK_BOOL(node->IsSegmentProtected("Bone"), true);
  CHECK_BOOL(node->SetSegmentCuttable("Bone", true), true);
  CHECK_BOOL(node->IsSegmentProtected("Bone"), false);

  // A protected segment cannot be made cuttable through the list setter.
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  node->SetCuttableSegmentIDs({ "Bone", "FacialNerve", "Bone", "" });
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  CHECK_INT(static_cast<int>(node->GetCuttableSegmentIDs().size()), 1);

  // Unknown segment: error, nothing changes.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(node->SetSegmentCuttable("NoSuchSegment", true), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_BOOL(node->IsSegmentCuttable("NoSuchSegment"), false);

  // Input changes are forwarded.
  const int inputEventsBefore = counter.InputDataModified;
  volume->GetImageData()->Modified();
  volume->InvokeCustomModifiedEvent(vtkMRMLVolumeNode::ImageDataModifiedEvent);
  CHECK_BOOL(counter.InputDataModified > inputEventsBefore, true);

  // Removing a segment drops its role.
  segmentation->GetSegmentation()->RemoveSegment("FacialNerve");
  CHECK_BOOL(node->IsSegmentProtected("FacialNerve"), false);

  // Removing a referenced node leaves the cut node valid, without the reference.
  scene->RemoveNode(segmentation);
  CHECK_NULL(node->GetSegmentationNode());
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(node->SetSegmentProtected("Sinus", true), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  scene->RemoveNode(volume);
  CHECK_NULL(node->GetAnatomyVolumeNode());
  return EXIT_SUCCESS;
}

int TestSaveReloadCopyUndo(const std::string& temporaryDir)
{
  vtkNew<vtkMRMLScene> scene;
  scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutNode>::New());
  vtkMRMLScalarVolumeNode* volume = AddVolume(scene);
  vtkMRMLSegmentationNode* segmentation = AddSegmentation(scene);
  vtkMRMLVolumeCutNode* node = vtkMRMLVolumeCutNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLVolumeCutNode", "Cut"));
  node->SetAndObserveAnatomyVolumeNodeID(volume->GetID());
  node->SetAndObserveSegmentationNodeID(segmentation->GetID());
  node->SetSegmentCuttable("Bone", true);
  node->SetSegmentProtected("FacialNerve", true);
  node->SetSegmentProtected("Sinus", true);
  node->SetSubVoxelFactor(4);

  // Save to XML and read back into a new scene.
  scene->SetSaveToXMLString(1);
  scene->Commit();
  std::string xml = scene->GetSceneXMLString();
  CHECK_BOOL(xml.find("protectedSegmentIDs=\"FacialNerve;Sinus\"") != std::string::npos, true);

  vtkNew<vtkMRMLScene> reloaded;
  reloaded->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutNode>::New());
  reloaded->SetLoadFromXMLString(1);
  reloaded->SetSceneXMLString(xml);
  reloaded->Import();
  vtkMRMLVolumeCutNode* read = vtkMRMLVolumeCutNode::SafeDownCast(reloaded->GetFirstNodeByClass("vtkMRMLVolumeCutNode"));
  CHECK_NOT_NULL(read);
  CHECK_INT(read->GetSubVoxelFactor(), 4);
  CHECK_BOOL(read->IsSegmentCuttable("Bone"), true);
  CHECK_BOOL(read->IsSegmentProtected("Sinus"), true);
  CHECK_NOT_NULL(read->GetSegmentationNode());
  CHECK_STD_STRING(read->GetSegmentationNode()->GetName(), "Anatomy");
  CHECK_NOT_NULL(read->GetAnatomyVolumeNode());

  // A .mrml file on disk, read with a URL, as Slicer's "Load scene" does.
  std::string sceneFile = temporaryDir + "/vtkMRMLVolumeCutNodeTest1.mrml";
  scene->SetSaveToXMLString(0);
  scene->SetURL(sceneFile.c_str());
  CHECK_BOOL(scene->Commit() != 0, true);
  vtkNew<vtkMRMLScene> fromFile;
  fromFile->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutNode>::New());
  fromFile->SetURL(sceneFile.c_str());
  fromFile->Import();
  vtkMRMLVolumeCutNode* fileNode = vtkMRMLVolumeCutNode::SafeDownCast(fromFile->GetFirstNodeByClass("vtkMRMLVolumeCutNode"));
  CHECK_NOT_NULL(fileNode);
  CHECK_BOOL(fileNode->IsSegmentProtected("FacialNerve"), true);
  vtksys::SystemTools::RemoveFile(sceneFile);

  // Copy.
  vtkNew<vtkMRMLVolumeCutNode> copy;
  copy->CopyContent(node);
  CHECK_INT(copy->GetSubVoxelFactor(), 4);
  CHECK_BOOL(copy->IsSegmentProtected("Sinus"), true);
  CHECK_BOOL(copy->IsSegmentCuttable("Bone"), true);

  // Undo and redo.
  scene->SetUndoOn();
  scene->SaveStateForUndo();
  node->SetSegmentCuttable("Sinus", true);
  node->SetSubVoxelFactor(1);
  CHECK_BOOL(node->IsSegmentCuttable("Sinus"), true);
  scene->Undo();
  node = vtkMRMLVolumeCutNode::SafeDownCast(scene->GetFirstNodeByClass("vtkMRMLVolumeCutNode"));
  CHECK_INT(node->GetSubVoxelFactor(), 4);
  CHECK_BOOL(node->IsSegmentCuttable("Sinus"), false);
  CHECK_BOOL(node->IsSegmentProtected("Sinus"), true);
  scene->Redo();
  node = vtkMRMLVolumeCutNode::SafeDownCast(scene->GetFirstNodeByClass("vtkMRMLVolumeCutNode"));
  CHECK_INT(node->GetSubVoxelFactor(), 1);
  CHECK_BOOL(node->IsSegmentCuttable("Sinus"), true);
  CHECK_BOOL(node->IsSegmentProtected("Sinus"), false);
  return EXIT_SUCCESS;
}

int TestCorruptXML()
{
  // Scene XML written by hand or damaged: unsupported values are rejected with
  // an error and the node keeps valid defaults.
  const char* xml = "<MRML version=\"Slicer4.4.0\">"
                    "<VolumeCut id=\"vtkMRMLVolumeCutNode1\" name=\"Cut\" subVoxelFactor=\"3\" protectedSegmentIDs=\"A;B\" cuttableSegmentIDs=\"B;C\"></VolumeCut>"
                    "</MRML>";
  vtkNew<vtkMRMLScene> scene;
  scene->RegisterNodeClass(vtkSmartPointer<vtkMRMLVolumeCutNode>::New());
  scene->SetLoadFromXMLString(1);
  scene->SetSceneXMLString(xml);
  // One error for the factor, one warning for B, listed in both roles.
  TESTING_OUTPUT_RESET();
  scene->Import();
  TESTING_OUTPUT_ASSERT_ERRORS(1);
  TESTING_OUTPUT_ASSERT_WARNINGS(1);
  TESTING_OUTPUT_RESET();
  vtkMRMLVolumeCutNode* node = vtkMRMLVolumeCutNode::SafeDownCast(scene->GetFirstNodeByClass("vtkMRMLVolumeCutNode"));
  CHECK_NOT_NULL(node);
  CHECK_INT(node->GetSubVoxelFactor(), 2);
  CHECK_BOOL(node->IsSegmentProtected("B"), true);
  CHECK_BOOL(node->IsSegmentCuttable("B"), false);
  CHECK_BOOL(node->IsSegmentCuttable("C"), true);
  return EXIT_SUCCESS;
}
} // namespace

int vtkMRMLVolumeCutNodeTest1(int argc, char* argv[])
{
  // As the Segmentations module does at start-up: segments need the
  // representations these rules provide.
  vtkSegmentationConverterFactory::GetInstance()->RegisterConverterRule(vtkSmartPointer<vtkBinaryLabelmapToClosedSurfaceConversionRule>::New());
  vtkSegmentationConverterFactory::GetInstance()->RegisterConverterRule(vtkSmartPointer<vtkClosedSurfaceToBinaryLabelmapConversionRule>::New());
  const std::string temporaryDir = argc > 1 ? argv[argc - 1] : ".";
  CHECK_EXIT_SUCCESS(TestDefaultsAndValidation());
  CHECK_EXIT_SUCCESS(TestReferencesAndRoles());
  CHECK_EXIT_SUCCESS(TestSaveReloadCopyUndo(temporaryDir));
  CHECK_EXIT_SUCCESS(TestCorruptXML());
  return EXIT_SUCCESS;
}
