/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef __qSlicerVolumeCuttingModuleWidget_h
#define __qSlicerVolumeCuttingModuleWidget_h

// Slicer includes
#include "qSlicerAbstractModuleWidget.h"

#include "qSlicerVolumeCuttingModuleExport.h"

class qSlicerVolumeCuttingModuleWidgetPrivate;
class vtkMRMLNode;

/// Thin panel over vtkSlicerVolumeCuttingLogic: choose the CT, its segmentation
/// and the cut session; segment bone; check the inputs. No logic lives here.
class Q_SLICER_QTMODULES_VOLUMECUTTING_EXPORT qSlicerVolumeCuttingModuleWidget : public qSlicerAbstractModuleWidget
{
  Q_OBJECT

public:
  typedef qSlicerAbstractModuleWidget Superclass;
  qSlicerVolumeCuttingModuleWidget(QWidget* parent = nullptr);
  ~qSlicerVolumeCuttingModuleWidget() override;

public slots:
  void onCutNodeChanged(vtkMRMLNode* node);
  void onAnatomyVolumeChanged(vtkMRMLNode* node);
  void onSegmentationChanged(vtkMRMLNode* node);
  void onSubVoxelFactorChanged(int index);
  void onSegmentBoneClicked();
  void onCheckInputsClicked();
  void updateWidgetFromMRML();

protected:
  QScopedPointer<qSlicerVolumeCuttingModuleWidgetPrivate> d_ptr;

  void setup() override;

private:
  Q_DECLARE_PRIVATE(qSlicerVolumeCuttingModuleWidget);
  Q_DISABLE_COPY(qSlicerVolumeCuttingModuleWidget);
};

#endif
