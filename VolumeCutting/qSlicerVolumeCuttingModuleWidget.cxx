/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// Qt includes
#include <QMessageBox>

// Slicer includes
#include "qSlicerVolumeCuttingModuleWidget.h"
#include "ui_qSlicerVolumeCuttingModuleWidget.h"

// VolumeCutting includes
#include <vtkMRMLVolumeCutNode.h>
#include <vtkSlicerVolumeCuttingLogic.h>

// MRML includes
#include <vtkMRMLMessageCollection.h>
#include <vtkMRMLScalarVolumeNode.h>
#include <vtkMRMLScene.h>
#include <vtkMRMLSegmentationNode.h>

// VTK includes
#include <vtkNew.h>

//-----------------------------------------------------------------------------
class qSlicerVolumeCuttingModuleWidgetPrivate : public Ui_qSlicerVolumeCuttingModuleWidget
{
public:
  vtkSlicerVolumeCuttingLogic* logic() const;
  vtkMRMLVolumeCutNode* cutNode() const;

  qSlicerVolumeCuttingModuleWidget* q_ptr{ nullptr };
};

//-----------------------------------------------------------------------------
vtkSlicerVolumeCuttingLogic* qSlicerVolumeCuttingModuleWidgetPrivate::logic() const
{
  return vtkSlicerVolumeCuttingLogic::SafeDownCast(q_ptr->logic());
}

//-----------------------------------------------------------------------------
vtkMRMLVolumeCutNode* qSlicerVolumeCuttingModuleWidgetPrivate::cutNode() const
{
  return vtkMRMLVolumeCutNode::SafeDownCast(this->CutNodeComboBox->currentNode());
}

//-----------------------------------------------------------------------------
qSlicerVolumeCuttingModuleWidget::qSlicerVolumeCuttingModuleWidget(QWidget* _parent)
  : Superclass(_parent)
  , d_ptr(new qSlicerVolumeCuttingModuleWidgetPrivate)
{
  d_ptr->q_ptr = this;
}

//-----------------------------------------------------------------------------
qSlicerVolumeCuttingModuleWidget::~qSlicerVolumeCuttingModuleWidget() = default;

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::setup()
{
  Q_D(qSlicerVolumeCuttingModuleWidget);
  d->setupUi(this);
  this->Superclass::setup();

  connect(d->CutNodeComboBox, SIGNAL(currentNodeChanged(vtkMRMLNode*)), this, SLOT(onCutNodeChanged(vtkMRMLNode*)));
  connect(d->AnatomyVolumeComboBox, SIGNAL(currentNodeChanged(vtkMRMLNode*)), this, SLOT(onAnatomyVolumeChanged(vtkMRMLNode*)));
  connect(d->SegmentationComboBox, SIGNAL(currentNodeChanged(vtkMRMLNode*)), this, SLOT(onSegmentationChanged(vtkMRMLNode*)));
  connect(d->SubVoxelFactorComboBox, SIGNAL(currentIndexChanged(int)), this, SLOT(onSubVoxelFactorChanged(int)));
  connect(d->SegmentBoneButton, SIGNAL(clicked()), this, SLOT(onSegmentBoneClicked()));
  connect(d->CheckInputsButton, SIGNAL(clicked()), this, SLOT(onCheckInputsClicked()));
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::onCutNodeChanged(vtkMRMLNode* node)
{
  Q_UNUSED(node);
  Q_D(qSlicerVolumeCuttingModuleWidget);
  qvtkReconnect(nullptr, d->cutNode(), vtkCommand::ModifiedEvent, this, SLOT(updateWidgetFromMRML()));
  this->updateWidgetFromMRML();
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::onAnatomyVolumeChanged(vtkMRMLNode* node)
{
  Q_D(qSlicerVolumeCuttingModuleWidget);
  if (d->cutNode())
  {
    d->cutNode()->SetAndObserveAnatomyVolumeNodeID(node ? node->GetID() : nullptr);
  }
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::onSegmentationChanged(vtkMRMLNode* node)
{
  Q_D(qSlicerVolumeCuttingModuleWidget);
  if (d->cutNode())
  {
    d->cutNode()->SetAndObserveSegmentationNodeID(node ? node->GetID() : nullptr);
  }
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::onSubVoxelFactorChanged(int index)
{
  Q_D(qSlicerVolumeCuttingModuleWidget);
  if (d->cutNode())
  {
    d->cutNode()->SetSubVoxelFactor(d->SubVoxelFactorComboBox->itemText(index).toInt());
  }
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::onSegmentBoneClicked()
{
  Q_D(qSlicerVolumeCuttingModuleWidget);
  vtkMRMLScalarVolumeNode* anatomy = vtkMRMLScalarVolumeNode::SafeDownCast(d->AnatomyVolumeComboBox->currentNode());
  vtkMRMLSegmentationNode* bone = d->logic()->CreateBoneSegmentation(anatomy, d->CorticalThresholdSpinBox->value(),
                                                                     d->TrabecularThresholdSpinBox->value(), d->SmoothingSpinBox->value());
  if (!bone)
  {
    QMessageBox::warning(this, tr("Segment bone"), tr("Bone segmentation failed: see the application log."));
    return;
  }
  d->SegmentationComboBox->setCurrentNode(bone);
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::onCheckInputsClicked()
{
  Q_D(qSlicerVolumeCuttingModuleWidget);
  vtkNew<vtkMRMLMessageCollection> messages;
  const bool valid = d->logic()->CheckInputs(d->cutNode(), messages);
  const QString text = QString::fromStdString(messages->GetAllMessagesAsString());
  d->StatusLabel->setText(valid ? (text.isEmpty() ? tr("Ready to cut.") : text) : text);
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModuleWidget::updateWidgetFromMRML()
{
  Q_D(qSlicerVolumeCuttingModuleWidget);
  vtkMRMLVolumeCutNode* cutNode = d->cutNode();
  d->InputsCollapsibleButton->setEnabled(cutNode != nullptr);
  if (!cutNode)
  {
    return;
  }
  QSignalBlocker blockVolume(d->AnatomyVolumeComboBox);
  QSignalBlocker blockSegmentation(d->SegmentationComboBox);
  QSignalBlocker blockFactor(d->SubVoxelFactorComboBox);
  d->AnatomyVolumeComboBox->setCurrentNode(cutNode->GetAnatomyVolumeNode());
  d->SegmentationComboBox->setCurrentNode(cutNode->GetSegmentationNode());
  d->SubVoxelFactorComboBox->setCurrentIndex(d->SubVoxelFactorComboBox->findText(QString::number(cutNode->GetSubVoxelFactor())));
}
