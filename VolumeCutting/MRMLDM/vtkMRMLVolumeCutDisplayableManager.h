/*==============================================================================

  VolumeCutting
  Licensed under the Apache License, Version 2.0 (the "License");

==============================================================================*/

/**
 * @class   vtkMRMLVolumeCutDisplayableManager
 * @brief   Shows each volume-cut node in 3D views through vtkVolumeCutVolumeMapper.
 *
 * For every vtkMRMLVolumeCutNode of the scene, one vtkVolume renders the
 * node's anatomy volume (placed by its IJK-to-RAS) minus the node's cut field
 * and its preview field if it has one, with exact cut surfaces and edges.
 * When the node has a segmentation, its segments visible in 3D (per-segment
 * 3D visibility) are drawn in their colours and per-segment 3D opacities:
 * cuttable segments by the CT surface (the node's SurfaceIsoValue) inside them, other segments by their own
 * shape. The segmentation's own 3D surfaces are independent: hide them
 * (display node Visibility3D) to see the cut anatomy alone. Thin-bone shading
 * follows the node.
 *
 * Cuts made through the logic invoke the node's CutModifiedEvent and the view
 * re-renders; the mapper uploads (GPU) or recasts (CPU) only what changed.
 *
 * Limitation: parent transforms of the anatomy volume are not applied.
 */

#ifndef vtkMRMLVolumeCutDisplayableManager_h
#define vtkMRMLVolumeCutDisplayableManager_h

#include "vtkSlicerVolumeCuttingModuleMRMLDisplayableManagerExport.h"

#include <vtkMRMLAbstractThreeDViewDisplayableManager.h>

#include <memory>

class vtkMRMLVolumeCutNode;
class vtkVolume;

class VTK_SLICER_VOLUMECUTTING_MODULE_MRMLDISPLAYABLEMANAGER_EXPORT vtkMRMLVolumeCutDisplayableManager
  : public vtkMRMLAbstractThreeDViewDisplayableManager
{
public:
  static vtkMRMLVolumeCutDisplayableManager* New();
  vtkTypeMacro(vtkMRMLVolumeCutDisplayableManager, vtkMRMLAbstractThreeDViewDisplayableManager);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The volume actor showing a cut node (nullptr if none), for tests and tools.
  vtkVolume* GetVolumeActor(vtkMRMLVolumeCutNode* cutNode);

protected:
  vtkMRMLVolumeCutDisplayableManager();
  ~vtkMRMLVolumeCutDisplayableManager() override;

  void SetMRMLSceneInternal(vtkMRMLScene* newScene) override;
  void OnMRMLSceneNodeAdded(vtkMRMLNode* node) override;
  void OnMRMLSceneNodeRemoved(vtkMRMLNode* node) override;
  void OnMRMLSceneEndClose() override;
  void UpdateFromMRMLScene() override;
  void ProcessMRMLNodesEvents(vtkObject* caller, unsigned long event, void* callData) override;

  void UpdatePipeline(vtkMRMLVolumeCutNode* node);
  void ObserveCutNode(vtkMRMLVolumeCutNode* node);
  /// While a stroke lasts the window asks for interactive frames, as Slicer's
  /// interactor styles do while the camera moves; the mapper then draws
  /// reduced images, and the full one once the stroke ends.
  void UpdateDesiredUpdateRate();

private:
  vtkMRMLVolumeCutDisplayableManager(const vtkMRMLVolumeCutDisplayableManager&) = delete;
  void operator=(const vtkMRMLVolumeCutDisplayableManager&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
