/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkSlicerVolumeCuttingLogic.h"
#include "vtkVolumeCutField.h"

// MRML includes
#include <vtkMRMLMessageCollection.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLTableNode.h>
#include <vtkMRMLSegmentationNode.h>

// SegmentationCore includes
#include <vtkOrientedImageData.h>
#include <vtkSegment.h>
#include <vtkSegmentation.h>
#include <vtkSegmentationConverter.h>

// vtkAddon includes
#include <vtkAddonTestingMacros.h>
#include <vtkTestingOutputWindow.h>

// VTK includes
#include <vtkCommand.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>

// STD includes
#include <array>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
// Ball of trabecular bone (radius 6 voxels) in a 2-voxel cortical shell, on an
// oblique, anisotropic grid: the labels must come back on exactly that grid.
vtkMRMLScalarVolumeNode* AddBallVolume(vtkMRMLScene* scene, int& expectedCortical, int& expectedTrabecular)
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(24, 24, 20);
  image->AllocateScalars(VTK_SHORT, 1);
  expectedCortical = 0;
  expectedTrabecular = 0;
  for (int k = 0; k < 20; ++k)
  {
    for (int j = 0; j < 24; ++j)
    {
      for (int i = 0; i < 24; ++i)
      {
        const double r = std::sqrt((i - 12.0) * (i - 12.0) + (j - 12.0) * (j - 12.0) + (k - 10.0) * (k - 10.0));
        short value = -1000;
        if (r <= 6.0)
        {
          value = 500;
          ++expectedTrabecular;
        }
        else if (r <= 8.0)
        {
          value = 1500;
          ++expectedCortical;
        }
        image->SetScalarComponentFromDouble(i, j, k, 0, value);
      }
    }
  }
  vtkMRMLScalarVolumeNode* volume = vtkMRMLScalarVolumeNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLScalarVolumeNode", "Ball"));
  volume->SetAndObserveImageData(image);
  vtkNew<vtkMatrix4x4> ijkToRas;
  // 30 degrees about the S axis, spacing 0.5 x 0.5 x 0.8 mm.
  const double c = std::cos(3.14159265358979 / 6.0);
  const double s = std::sin(3.14159265358979 / 6.0);
  const double spacing[3] = { 0.5, 0.5, 0.8 };
  const double axes[3][3] = { { c, s, 0 }, { -s, c, 0 }, { 0, 0, 1 } };
  for (int row = 0; row < 3; ++row)
  {
    for (int column = 0; column < 3; ++column)
    {
      ijkToRas->SetElement(row, column, axes[column][row] * spacing[column]);
    }
  }
  ijkToRas->SetElement(0, 3, -10.0);
  ijkToRas->SetElement(1, 3, 5.0);
  ijkToRas->SetElement(2, 3, 30.0);
  volume->SetIJKToRASMatrix(ijkToRas);
  return volume;
}

int CountVoxels(vtkOrientedImageData* labelmap)
{
  int count = 0;
  int extent[6];
  labelmap->GetExtent(extent);
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      for (int i = extent[0]; i <= extent[1]; ++i)
      {
        count += labelmap->GetScalarComponentAsDouble(i, j, k, 0) > 0;
      }
    }
  }
  return count;
}

int TestBoneSegmentationAndCutNode()
{
  vtkNew<vtkMRMLScene> scene;
  vtkNew<vtkSlicerVolumeCuttingLogic> logic;
  logic->SetMRMLScene(scene);
  CHECK_BOOL(scene->IsNodeClassRegistered("vtkMRMLVolumeCutNode"), true);

  int expectedCortical = 0;
  int expectedTrabecular = 0;
  vtkMRMLScalarVolumeNode* volume = AddBallVolume(scene, expectedCortical, expectedTrabecular);
  vtkMRMLSegmentationNode* bone = logic->CreateBoneSegmentation(volume);
  CHECK_NOT_NULL(bone);
  vtkSegmentation* segmentation = bone->GetSegmentation();
  CHECK_INT(segmentation->GetNumberOfSegments(), 2);
  CHECK_NOT_NULL(segmentation->GetSegment(vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID()));

  vtkOrientedImageData* cortical = bone->GetBinaryLabelmapInternalRepresentation(vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID());
  vtkOrientedImageData* trabecular = bone->GetBinaryLabelmapInternalRepresentation(vtkSlicerVolumeCuttingLogic::GetTrabecularBoneSegmentID());
  CHECK_NOT_NULL(cortical);
  CHECK_NOT_NULL(trabecular);
  CHECK_INT(CountVoxels(cortical), expectedCortical);
  CHECK_INT(CountVoxels(trabecular), expectedTrabecular);

  // Same grid as the CT, oblique axes included.
  vtkNew<vtkMatrix4x4> ijkToRas;
  volume->GetIJKToRASMatrix(ijkToRas);
  vtkNew<vtkMatrix4x4> labelmapToWorld;
  cortical->GetImageToWorldMatrix(labelmapToWorld);
  for (int row = 0; row < 4; ++row)
  {
    for (int column = 0; column < 4; ++column)
    {
      CHECK_DOUBLE_TOLERANCE(labelmapToWorld->GetElement(row, column), ijkToRas->GetElement(row, column), 1e-9);
    }
  }

  vtkMRMLVolumeCutNode* cutNode = logic->AddVolumeCutNode(volume, bone);
  CHECK_NOT_NULL(cutNode);
  CHECK_POINTER(cutNode->GetAnatomyVolumeNode(), volume);
  CHECK_POINTER(cutNode->GetSegmentationNode(), bone);
  CHECK_BOOL(cutNode->SetSegmentCuttable(vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID(), true), true);

  vtkNew<vtkMRMLMessageCollection> messages;
  CHECK_BOOL(logic->CheckInputs(cutNode, messages), true);
  CHECK_INT(messages->GetNumberOfMessages(), 0);
  return EXIT_SUCCESS;
}

int TestCheckInputsReportsProblems()
{
  vtkNew<vtkMRMLScene> scene;
  vtkNew<vtkSlicerVolumeCuttingLogic> logic;
  logic->SetMRMLScene(scene);
  int cortical = 0;
  int trabecular = 0;
  vtkMRMLScalarVolumeNode* volume = AddBallVolume(scene, cortical, trabecular);

  // Null node and missing anatomy are errors.
  vtkNew<vtkMRMLMessageCollection> messages;
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(logic->CheckInputs(nullptr, messages), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  vtkMRMLVolumeCutNode* cutNode = logic->AddVolumeCutNode(nullptr, nullptr);
  messages->ClearMessages();
  TESTING_OUTPUT_IGNORE_WARNINGS_ERRORS_BEGIN();
  CHECK_BOOL(logic->CheckInputs(cutNode, messages), false);
  TESTING_OUTPUT_IGNORE_WARNINGS_ERRORS_END();
  CHECK_INT(messages->GetNumberOfMessagesOfType(vtkCommand::ErrorEvent), 1);
  CHECK_INT(messages->GetNumberOfMessagesOfType(vtkCommand::WarningEvent), 1);

  // A segmentation on another grid is a warning, not an error.
  vtkMRMLSegmentationNode* other = vtkMRMLSegmentationNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLSegmentationNode", "Other grid"));
  vtkNew<vtkOrientedImageData> mask;
  mask->SetDimensions(10, 10, 10);
  mask->SetSpacing(1.0, 1.0, 1.0);
  mask->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  vtkNew<vtkSegment> segment;
  segment->AddRepresentation(vtkSegmentationConverter::GetBinaryLabelmapRepresentationName(), mask);
  other->GetSegmentation()->AddSegment(segment, "Nerve");
  cutNode->SetAndObserveAnatomyVolumeNodeID(volume->GetID());
  cutNode->SetAndObserveSegmentationNodeID(other->GetID());
  messages->ClearMessages();
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  CHECK_BOOL(logic->CheckInputs(cutNode, messages), true);
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  CHECK_INT(messages->GetNumberOfMessagesOfType(vtkCommand::WarningEvent), 1);
  CHECK_BOOL(messages->GetAllMessagesAsString().find("voxel grid") != std::string::npos, true);

  // An anatomy without voxels is an error; so is a bone segmentation of it.
  vtkMRMLScalarVolumeNode* empty = vtkMRMLScalarVolumeNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLScalarVolumeNode", "Empty"));
  cutNode->SetAndObserveAnatomyVolumeNodeID(empty->GetID());
  messages->ClearMessages();
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(logic->CheckInputs(cutNode, messages), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  const int nodesBefore = scene->GetNumberOfNodes();
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_NULL(logic->CreateBoneSegmentation(empty));
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_INT(scene->GetNumberOfNodes(), nodesBefore);

  // Thresholds in the wrong order: error, nothing added.
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_NULL(logic->CreateBoneSegmentation(volume, 100.0, 500.0));
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_INT(scene->GetNumberOfNodes(), nodesBefore);
  return EXIT_SUCCESS;
}
int TestStrokesAndRemovedVolumePerSegment()
{
  vtkNew<vtkMRMLScene> scene;
  vtkNew<vtkSlicerVolumeCuttingLogic> logic;
  logic->SetMRMLScene(scene);
  int cortical = 0;
  int trabecular = 0;
  vtkMRMLScalarVolumeNode* volume = AddBallVolume(scene, cortical, trabecular);
  vtkMRMLSegmentationNode* bone = logic->CreateBoneSegmentation(volume);
  vtkMRMLVolumeCutNode* cutNode = logic->AddVolumeCutNode(volume, bone);

  // The ball's centre in RAS: voxel (12, 12, 10).
  vtkNew<vtkMatrix4x4> ijkToRas;
  volume->GetIJKToRASMatrix(ijkToRas);
  const double centerIjk[4] = { 12.0, 12.0, 10.0, 1.0 };
  double center[4];
  ijkToRas->MultiplyPoint(centerIjk, center);

  // Tools affect only cuttable segments.
  cutNode->SetCuttableSegmentIDs({ vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID(), vtkSlicerVolumeCuttingLogic::GetTrabecularBoneSegmentID() });

  // A 2 mm burr at the centre stays inside the trabecular ball (semi-axes 3, 3, 4.8 mm).
  CHECK_BOOL(logic->BeginStroke(cutNode), true);
  CHECK_BOOL(logic->CutSphereSweep(cutNode, center, center, 2.0), true);
  CHECK_BOOL(logic->EndStroke(cutNode), true);
  const double sphere = 4.0 / 3.0 * 3.14159265358979 * 8.0;
  const double total = logic->GetRemovedVolume(cutNode);
  CHECK_BOOL(std::abs(total - sphere) / sphere < 0.005, true);
  const double inTrabecular = logic->GetRemovedVolumeInSegment(cutNode, vtkSlicerVolumeCuttingLogic::GetTrabecularBoneSegmentID());
  const double inCortical = logic->GetRemovedVolumeInSegment(cutNode, vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID());
  CHECK_DOUBLE_TOLERANCE(inTrabecular, total, 1e-3 * total);
  CHECK_DOUBLE_TOLERANCE(inCortical, 0.0, 1e-9);

  // A sweep out through the shell removes cortical bone too.
  const double outsideIjk[4] = { 22.0, 12.0, 10.0, 1.0 };
  double outside[4];
  ijkToRas->MultiplyPoint(outsideIjk, outside);
  CHECK_BOOL(logic->CutSphereSweep(cutNode, center, outside, 1.0), true);
  CHECK_BOOL(logic->GetRemovedVolumeInSegment(cutNode, vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID()) > 1.0, true);
  CHECK_BOOL(logic->GetCutField(cutNode)->GetNumberOfUndoSteps() == 2, true);
  CHECK_BOOL(logic->UndoStroke(cutNode), true);
  CHECK_DOUBLE_TOLERANCE(logic->GetRemovedVolume(cutNode), total, 1e-9);
  CHECK_BOOL(logic->RedoStroke(cutNode), true);

  // Refused strokes keep the cut; unknown segments are errors.
  const double volumeBefore = logic->GetRemovedVolume(cutNode);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_BOOL(logic->CutSphereSweep(cutNode, center, center, -1.0), false);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_DOUBLE(logic->GetRemovedVolumeInSegment(cutNode, "NoSuchSegment"), -1.0);
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  CHECK_DOUBLE_TOLERANCE(logic->GetRemovedVolume(cutNode), volumeBefore, 1e-12);

  // Protecting the cortical shell: a new sweep out through it removes no
  // more cortical bone, and the contact names the segment.
  const double corticalBefore = logic->GetRemovedVolumeInSegment(cutNode, vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID());
  CHECK_BOOL(cutNode->SetSegmentProtected(vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID(), true), true);
  const double upIjk[4] = { 12.0, 22.0, 10.0, 1.0 };
  double up[4];
  ijkToRas->MultiplyPoint(upIjk, up);
  // The stored samples of the cortical voxels (at their sub-voxel centres,
  // where interpolation returns the sample itself) that were not removed stay
  // not removed (their distances may shrink: the cut now reaches the face).
  vtkVolumeCutField* field = logic->GetCutField(cutNode);
  std::vector<std::array<double, 3>> corticalCentres;
  for (int k = 0; k < 20; ++k)
  {
    for (int j = 12; j < 24; ++j)
    {
      const double r = std::sqrt((j - 12.0) * (j - 12.0) + (k - 10.0) * (k - 10.0));
      if (r > 6.0 && r <= 8.0)
      {
        for (double dj : { -0.25, 0.25 })
        {
          for (double dk : { -0.25, 0.25 })
          {
            for (double di : { -0.25, 0.25 })
            {
              const double index[4] = { 12.0 + di, j + dj, k + dk, 1.0 };
              double ras[4];
              ijkToRas->MultiplyPoint(index, ras);
              corticalCentres.push_back({ ras[0], ras[1], ras[2] });
            }
          }
        }
      }
    }
  }
  std::vector<double> before;
  for (const auto& point : corticalCentres)
  {
    before.push_back(field->GetSignedDistance(point.data()));
  }
  CHECK_BOOL(logic->CutSphereSweep(cutNode, center, up, 1.0), true);
  for (size_t n = 0; n < corticalCentres.size(); ++n)
  {
    if (before[n] > 0.0)
    {
      CHECK_BOOL(field->GetSignedDistance(corticalCentres[n].data()) > 0.0, true);
    }
  }
  // The volume reported inside the protected segment does not grow: samples
  // the field did not remove report nothing, whatever the ramp of the new cut
  // surface on the segment's face (what was cut before it was protected still counts).
  const double corticalAfter = logic->GetRemovedVolumeInSegment(cutNode, vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID());
  std::cout << "removed in the protected cortex: before " << corticalBefore << " mm3, after " << corticalAfter << " mm3" << std::endl;
  CHECK_BOOL(corticalAfter <= corticalBefore + 1e-9, true);
  CHECK_STD_STRING(logic->GetContactSegmentID(cutNode), vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID());
  CHECK_BOOL(logic->GetCutField(cutNode)->GetMaximumContactDepth() > 0.5, true);

  // The shielded cortex reports exactly nothing removed where the field did
  // not remove its voxels' inside; the contact is in the contact table.
  vtkMRMLTableNode* contacts = logic->GetContactTableNode(cutNode);
  CHECK_NOT_NULL(contacts);
  CHECK_INT(contacts->GetNumberOfRows(), 1);
  CHECK_STD_STRING(contacts->GetCellText(0, 0), vtkSlicerVolumeCuttingLogic::GetCorticalBoneSegmentID());

  // Another sub-voxel factor means another grid: the cut is resampled onto
  // it with a warning, never dropped.
  const double removedBefore = logic->GetRemovedVolume(cutNode);
  cutNode->SetSubVoxelFactor(4);
  TESTING_OUTPUT_ASSERT_WARNINGS_BEGIN();
  const double removedAfter = logic->GetRemovedVolume(cutNode);
  TESTING_OUTPUT_ASSERT_WARNINGS_END();
  CHECK_INT(logic->GetCutField(cutNode)->GetSubVoxelFactor(), 4);
  std::cout << "factor 2 -> 4: removed " << removedBefore << " -> " << removedAfter << " mm3" << std::endl;
  CHECK_DOUBLE_TOLERANCE(removedAfter, removedBefore, 0.01 * removedBefore);

  // Removing the node releases its field; a node without anatomy has none.
  vtkMRMLVolumeCutNode* empty = logic->AddVolumeCutNode(nullptr, nullptr);
  TESTING_OUTPUT_ASSERT_ERRORS_BEGIN();
  CHECK_NULL(logic->GetCutField(empty));
  TESTING_OUTPUT_ASSERT_ERRORS_END();
  scene->RemoveNode(cutNode);
  return EXIT_SUCCESS;
}
} // namespace

int vtkSlicerVolumeCuttingLogicTest1(int, char*[])
{
  CHECK_EXIT_SUCCESS(TestBoneSegmentationAndCutNode());
  CHECK_EXIT_SUCCESS(TestCheckInputsReportsProblems());
  CHECK_EXIT_SUCCESS(TestStrokesAndRemovedVolumePerSegment());
  return EXIT_SUCCESS;
}
