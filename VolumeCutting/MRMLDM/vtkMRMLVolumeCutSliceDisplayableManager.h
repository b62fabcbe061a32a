/*==============================================================================

  VolumeCutting
  Licensed under the Apache License, Version 2.0 (the "License");

==============================================================================*/

/**
 * @class   vtkMRMLVolumeCutSliceDisplayableManager
 * @brief   Shows where each slice view cuts the removed region of a volume-cut node.
 *
 * For every vtkMRMLVolumeCutNode with a cut field, a slice view draws the
 * outline of the removed region where its plane meets the cut surface, and a
 * fill of the removed part of the plane at an opacity, in the node's
 * SliceColor (the node's Slice* properties), so that scrolling a slice, or an
 * oblique cut plane, shows the cavity in depth (Pflesser et al. 2002, Fig.
 * 5d).
 *
 * Both come from the field's own signed distance (vtkVolumeCutField::
 * GetSignedDistance, the same reconstruction the 3D view and the exports use),
 * sampled on the slice plane no coarser than the field's smallest sub-voxel
 * spacing, only where the plane crosses allocated bricks (no cut can lie
 * elsewhere) and within the view, then contoured at 0 (outline) and clipped
 * at 0 (fill) in the view's XY coordinates. Any slice orientation and any
 * IJK-to-RAS of the field (oblique, flipped) work, since samples are placed
 * in RAS.
 *
 * Updates are lazy: the node's CutModifiedEvent, its display properties and
 * the slice node only request a render; the plane is resampled when the
 * view renders and the field's stamp, the slice geometry or the visibility
 * changed since the last sampling. A stroke of a thousand poses then costs
 * one resampling per frame, and a field written directly by a haptic thread
 * (no events) is resampled at the next frame the view draws.
 *
 * Limitation: parent transforms of the anatomy volume are not applied (as in
 * vtkMRMLVolumeCutDisplayableManager).
 */

#ifndef vtkMRMLVolumeCutSliceDisplayableManager_h
#define vtkMRMLVolumeCutSliceDisplayableManager_h

#include "vtkSlicerVolumeCuttingModuleMRMLDisplayableManagerExport.h"

#include <vtkMRMLAbstractSliceViewDisplayableManager.h>

#include <memory>

class vtkActor2D;
class vtkMRMLVolumeCutNode;
class vtkPolyData;

class VTK_SLICER_VOLUMECUTTING_MODULE_MRMLDISPLAYABLEMANAGER_EXPORT vtkMRMLVolumeCutSliceDisplayableManager
  : public vtkMRMLAbstractSliceViewDisplayableManager
{
public:
  static vtkMRMLVolumeCutSliceDisplayableManager* New();
  vtkTypeMacro(vtkMRMLVolumeCutSliceDisplayableManager, vtkMRMLAbstractSliceViewDisplayableManager);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * What this view draws for a cut node, brought up to date first: the
   * outline (lines) and the fill (polygons) of the removed region in the
   * slice view's XY coordinates (pixels, z = 0; the slice node's XYToRAS
   * gives RAS), and the actors drawing them. nullptr for a node this view
   * does not show. For tests and tools.
   */
  vtkPolyData* GetOutline(vtkMRMLVolumeCutNode* cutNode);
  vtkPolyData* GetFill(vtkMRMLVolumeCutNode* cutNode);
  vtkActor2D* GetOutlineActor(vtkMRMLVolumeCutNode* cutNode);
  vtkActor2D* GetFillActor(vtkMRMLVolumeCutNode* cutNode);
  ///@}

  ///@{
  /**
   * The spacing (mm) of the distance samples on the slice plane and how many
   * were evaluated at the last sampling of a cut node (0 and 0 before any, or
   * when the plane crosses no allocated brick).
   */
  double GetSampleSpacing(vtkMRMLVolumeCutNode* cutNode);
  vtkIdType GetNumberOfSamples(vtkMRMLVolumeCutNode* cutNode);
  ///@}

  ///@{
  /**
   * Set/get the most distance samples taken on the plane for one node. A
   * section needing more (a cut through the whole of a large volume in a
   * zoomed-out view) is sampled more coarsely, with a warning. Default is
   * 16 million.
   */
  vtkSetClampMacro(MaximumNumberOfSamples, vtkIdType, 1024, VTK_ID_MAX);
  vtkGetMacro(MaximumNumberOfSamples, vtkIdType);
  ///@}

protected:
  vtkMRMLVolumeCutSliceDisplayableManager();
  ~vtkMRMLVolumeCutSliceDisplayableManager() override;

  void AdditionalInitializeStep() override;
  void SetMRMLSceneInternal(vtkMRMLScene* newScene) override;
  void OnMRMLSceneNodeAdded(vtkMRMLNode* node) override;
  void OnMRMLSceneNodeRemoved(vtkMRMLNode* node) override;
  void OnMRMLSceneEndClose() override;
  void UpdateFromMRMLScene() override;
  void ProcessMRMLNodesEvents(vtkObject* caller, unsigned long event, void* callData) override;
  void OnMRMLSliceNodeModifiedEvent() override;

  /// Called when the view starts rendering: brings every node's drawing up to date.
  void OnRenderStart();
  /// Resamples a node's section if what it depends on changed; applies its display properties.
  void UpdatePipeline(vtkMRMLVolumeCutNode* cutNode);

  vtkIdType MaximumNumberOfSamples{ 16 * 1024 * 1024 };

private:
  vtkMRMLVolumeCutSliceDisplayableManager(const vtkMRMLVolumeCutSliceDisplayableManager&) = delete;
  void operator=(const vtkMRMLVolumeCutSliceDisplayableManager&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Impl;
};

#endif
