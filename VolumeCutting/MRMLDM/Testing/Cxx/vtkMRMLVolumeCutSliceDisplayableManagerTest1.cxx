/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// VolumeCutting includes
#include "vtkMRMLVolumeCutNode.h"
#include "vtkMRMLVolumeCutSliceDisplayableManager.h"
#include "vtkSlicerVolumeCuttingLogic.h"

// MRML includes
#include <vtkMRMLDisplayableManagerGroup.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSliceNode.h>

// vtkAddon includes
#include <vtkAddonTestingMacros.h>

// VTK includes
#include <vtkActor2D.h>
#include <vtkAutoInit.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>

// STD includes
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>

VTK_MODULE_INIT(vtkRenderingOpenGL2);

namespace
{
const double Spacing[3] = { 0.6, 0.7, 1.3 };
const double Center[3] = { 1.37, -0.82, 0.55 };
const double Radius = 5.0;

/// Largest distance error (mm) of the outline's points, taken to RAS, from the
/// circle in which the plane through origin with unit normal cuts the sphere:
/// around the centre's projection onto the plane.
double OutlineCircleError(vtkMRMLVolumeCutSliceDisplayableManager* manager, vtkMRMLVolumeCutNode* cutNode, vtkMRMLSliceNode* sliceNode,
  const double origin[3], const double normal[3], vtkIdType& points)
{
  vtkPolyData* outline = manager->GetOutline(cutNode);
  points = outline ? outline->GetNumberOfPoints() : 0;
  const double height = (origin[0] - Center[0]) * normal[0] + (origin[1] - Center[1]) * normal[1] + (origin[2] - Center[2]) * normal[2];
  const double expected = std::sqrt(Radius * Radius - height * height);
  const double circleCenter[3] = { Center[0] + height * normal[0], Center[1] + height * normal[1], Center[2] + height * normal[2] };
  double worst = 0.0;
  for (vtkIdType n = 0; n < points; ++n)
  {
    double xy[4] = { 0.0, 0.0, 0.0, 1.0 };
    outline->GetPoint(n, xy);
    xy[2] = 0.0;
    double ras[4];
    sliceNode->GetXYToRAS()->MultiplyPoint(xy, ras);
    double offPlane = 0.0;
    double inPlane[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      offPlane += (ras[axis] - origin[axis]) * normal[axis];
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      inPlane[axis] = ras[axis] - circleCenter[axis];
    }
    const double radius = std::sqrt(inPlane[0] * inPlane[0] + inPlane[1] * inPlane[1] + inPlane[2] * inPlane[2]);
    worst = std::max({ worst, std::abs(radius - expected), std::abs(offPlane) });
  }
  return worst;
}

void SetPlane(vtkMRMLSliceNode* sliceNode, const double origin[3], const double normal[3])
{
  // Any in-plane axes: the slice's x axis across the normal and R.
  double x[3] = { 0.0, normal[2], -normal[1] };
  if (std::abs(normal[0]) > 0.9)
  {
    x[0] = -normal[2];
    x[1] = 0.0;
    x[2] = normal[0];
  }
  const double length = std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  const double y[3] = { (normal[1] * x[2] - normal[2] * x[1]) / length, (normal[2] * x[0] - normal[0] * x[2]) / length,
    (normal[0] * x[1] - normal[1] * x[0]) / length };
  vtkMatrix4x4* sliceToRas = sliceNode->GetSliceToRAS();
  for (int row = 0; row < 3; ++row)
  {
    sliceToRas->SetElement(row, 0, x[row] / length);
    sliceToRas->SetElement(row, 1, y[row]);
    sliceToRas->SetElement(row, 2, normal[row]);
    sliceToRas->SetElement(row, 3, origin[row]);
  }
  sliceNode->UpdateMatrices();
}
} // namespace

//----------------------------------------------------------------------------
int vtkMRMLVolumeCutSliceDisplayableManagerTest1(int vtkNotUsed(argc), char* vtkNotUsed(argv)[])
{
  vtkNew<vtkMRMLScene> scene;
  // Displayable managers look up the scene's interaction node, as in Slicer.
  scene->AddNewNodeByClass("vtkMRMLInteractionNode");
  vtkNew<vtkSlicerVolumeCuttingLogic> logic;
  logic->SetMRMLScene(scene);

  // A CT on a grid with anisotropic spacing and the x axis flipped.
  vtkNew<vtkImageData> image;
  image->SetDimensions(40, 36, 24);
  image->AllocateScalars(VTK_SHORT, 1);
  std::fill_n(static_cast<short*>(image->GetScalarPointer()), 40 * 36 * 24, static_cast<short>(1000));
  vtkMRMLScalarVolumeNode* volume = vtkMRMLScalarVolumeNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLScalarVolumeNode", "CT"));
  volume->SetAndObserveImageData(image);
  vtkNew<vtkMatrix4x4> ijkToRas;
  ijkToRas->SetElement(0, 0, -Spacing[0]);
  ijkToRas->SetElement(1, 1, Spacing[1]);
  ijkToRas->SetElement(2, 2, Spacing[2]);
  ijkToRas->SetElement(0, 3, 19.5 * Spacing[0]);
  ijkToRas->SetElement(1, 3, -17.5 * Spacing[1]);
  ijkToRas->SetElement(2, 3, -11.5 * Spacing[2]);
  volume->SetIJKToRASMatrix(ijkToRas);
  vtkMRMLVolumeCutNode* cutNode = logic->AddVolumeCutNode(volume, nullptr);
  CHECK_NOT_NULL(cutNode);

  // A slice view: its node, an offscreen window and our displayable manager.
  vtkMRMLSliceNode* sliceNode = vtkMRMLSliceNode::SafeDownCast(scene->AddNewNodeByClass("vtkMRMLSliceNode", "Red"));
  sliceNode->SetLayoutName("Red");
  sliceNode->SetDimensions(200, 200, 1);
  sliceNode->SetFieldOfView(15.0, 15.0, 1.0);
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(200, 200);
  window->AddRenderer(renderer);
  // Displayable managers observe the view's interactor.
  vtkNew<vtkRenderWindowInteractor> interactor;
  interactor->SetRenderWindow(window);
  vtkNew<vtkMRMLDisplayableManagerGroup> group;
  group->SetRenderer(renderer);
  vtkNew<vtkMRMLVolumeCutSliceDisplayableManager> manager;
  group->AddDisplayableManager(manager);
  group->SetMRMLDisplayableNode(sliceNode);
  CHECK_NOT_NULL(manager->GetOutline(cutNode));
  CHECK_INT(manager->GetOutline(cutNode)->GetNumberOfPoints(), 0);

  CHECK_BOOL(logic->CutSphereSweep(cutNode, Center, Center, Radius), true);
  const double tolerance = 0.1 * Spacing[0];
  const double axial[3] = { 0.0, 0.0, 1.0 };
  for (double height : { 0.0, 2.7, -4.2 })
  {
    const double origin[3] = { Center[0] + 0.4, Center[1] - 0.3, Center[2] + height };
    SetPlane(sliceNode, origin, axial);
    vtkIdType points = 0;
    const double error = OutlineCircleError(manager, cutNode, sliceNode, origin, axial, points);
    std::cout << "axial plane at " << height << " mm: " << points << " outline points, largest error " << error << " mm" << std::endl;
    CHECK_BOOL(points > 50, true);
    CHECK_BOOL(error < tolerance, true);
  }
  const double tilted[3] = { 0.48, -0.36, 0.8 }; // unit length
  const double obliqueOrigin[3] = { Center[0] + 1.9 * tilted[0], Center[1] + 1.9 * tilted[1], Center[2] + 1.9 * tilted[2] };
  SetPlane(sliceNode, obliqueOrigin, tilted);
  vtkIdType points = 0;
  const double obliqueError = OutlineCircleError(manager, cutNode, sliceNode, obliqueOrigin, tilted, points);
  std::cout << "oblique plane: " << points << " outline points, largest error " << obliqueError << " mm" << std::endl;
  CHECK_BOOL(points > 50, true);
  CHECK_BOOL(obliqueError < tolerance, true);
  CHECK_BOOL(manager->GetFill(cutNode)->GetNumberOfPolys() > 0, true);
  CHECK_BOOL(manager->GetSampleSpacing(cutNode) > 0.0 && manager->GetSampleSpacing(cutNode) <= 0.5 * Spacing[0] + 1e-12, true);

  // A frame brings the drawing up to date by itself.
  SetPlane(sliceNode, Center, axial);
  window->Render();
  CHECK_BOOL(manager->GetOutlineActor(cutNode)->GetVisibility() != 0, true);
  CHECK_BOOL(manager->GetFillActor(cutNode)->GetVisibility() != 0, true);
  cutNode->SetSliceFillVisibility(false);
  window->Render();
  CHECK_BOOL(manager->GetFillActor(cutNode)->GetVisibility() != 0, false);

  CHECK_BOOL(logic->UndoStroke(cutNode), true);
  window->Render();
  CHECK_INT(manager->GetOutline(cutNode)->GetNumberOfPoints(), 0);
  CHECK_BOOL(manager->GetOutlineActor(cutNode)->GetVisibility() != 0, false);

  std::ostringstream printed;
  manager->Print(printed);
  CHECK_BOOL(printed.str().find("Cut nodes shown: 1") != std::string::npos, true);

  scene->RemoveNode(cutNode);
  CHECK_NULL(manager->GetOutline(cutNode));
  group->SetMRMLDisplayableNode(nullptr);
  return EXIT_SUCCESS;
}
