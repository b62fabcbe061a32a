/*==============================================================================

  VolumeCutting
  Licensed under the Apache License, Version 2.0 (the "License");

==============================================================================*/

/**
 * @class   vtkMRMLVolumeCutToolDisplayableManager
 * @brief   Shows each cutting tool (vtkMRMLVolumeCutToolNode) in 3D views where its pose puts it.
 *
 * The glyph is the tool's cutting part at its true size (ball, cylinder,
 * disk, blade or mesh, in the tool's frame) and, when the display node says
 * ShowAxis, its shaft along +z towards the handpiece; it follows the tool's
 * parent transform, so a mouse, a haptic device or a replay moving the tool
 * (vtkSlicerVolumeCuttingLogic::MoveActiveTool) moves the glyph. Colour,
 * opacity and visibility come from the tool's display node
 * (vtkMRMLVolumeCutToolDisplayNode).
 */

#ifndef vtkMRMLVolumeCutToolDisplayableManager_h
#define vtkMRMLVolumeCutToolDisplayableManager_h

#include "vtkSlicerVolumeCuttingModuleMRMLDisplayableManagerExport.h"

#include <vtkMRMLAbstractThreeDViewDisplayableManager.h>

#include <memory>

class vtkActor;
class vtkMRMLVolumeCutToolNode;

class VTK_SLICER_VOLUMECUTTING_MODULE_MRMLDISPLAYABLEMANAGER_EXPORT vtkMRMLVolumeCutToolDisplayableManager
  : public vtkMRMLAbstractThreeDViewDisplayableManager
{
public:
  static vtkMRMLVolumeCutToolDisplayableManager* New();
  vtkTypeMacro(vtkMRMLVolumeCutToolDisplayableManager, vtkMRMLAbstractThreeDViewDisplayableManager);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The actor showing a tool's cutting part (nullptr if none), for tests and picking.
  vtkActor* GetToolActor(vtkMRMLVolumeCutToolNode* toolNode);
  /// The actor showing a tool's shaft (nullptr if none).
  vtkActor* GetShaftActor(vtkMRMLVolumeCutToolNode* toolNode);

protected:
  vtkMRMLVolumeCutToolDisplayableManager();
  ~vtkMRMLVolumeCutToolDisplayableManager() override;

  void SetMRMLSceneInternal(vtkMRMLScene* newScene) override;
  void OnMRMLSceneNodeAdded(vtkMRMLNode* node) override;
  void OnMRMLSceneNodeRemoved(vtkMRMLNode* node) override;
  void OnMRMLSceneEndClose() override;
  void UpdateFromMRMLScene() override;
  void ProcessMRMLNodesEvents(vtkObject* caller, unsigned long event, void* callData) override;

  /// Build or update the glyph of one tool (geometry only when it changed).
  void UpdatePipeline(vtkMRMLVolumeCutToolNode* toolNode);
  void RemovePipeline(vtkMRMLVolumeCutToolNode* toolNode);

private:
  vtkMRMLVolumeCutToolDisplayableManager(const vtkMRMLVolumeCutToolDisplayableManager&) = delete;
  void operator=(const vtkMRMLVolumeCutToolDisplayableManager&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
