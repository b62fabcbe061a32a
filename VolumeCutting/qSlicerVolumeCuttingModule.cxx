/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

// VolumeCutting Logic includes
#include <vtkSlicerVolumeCuttingLogic.h>

// DisplayableManager initialization
#include <vtkAutoInit.h>
VTK_MODULE_INIT(vtkSlicerVolumeCuttingModuleMRMLDisplayableManager)

// MRMLDisplayableManager includes
#include <vtkMRMLSliceViewDisplayableManagerFactory.h>
#include <vtkMRMLThreeDViewDisplayableManagerFactory.h>

// VolumeCutting includes
#include "qSlicerVolumeCuttingModule.h"
#include "qSlicerVolumeCuttingModuleWidget.h"

//-----------------------------------------------------------------------------
class qSlicerVolumeCuttingModulePrivate
{
public:
  qSlicerVolumeCuttingModulePrivate() = default;
};

//-----------------------------------------------------------------------------
qSlicerVolumeCuttingModule::qSlicerVolumeCuttingModule(QObject* _parent)
  : Superclass(_parent)
  , d_ptr(new qSlicerVolumeCuttingModulePrivate)
{
}

//-----------------------------------------------------------------------------
qSlicerVolumeCuttingModule::~qSlicerVolumeCuttingModule() = default;

//-----------------------------------------------------------------------------
QString qSlicerVolumeCuttingModule::helpText() const
{
  return tr("Virtual bone drilling and volume cutting on CT. Segment the anatomy, mark which segments "
            "a tool may cut and which are protected, then cut. The anatomy is never modified: the removed "
            "region is kept in its own sub-voxel cut field, so every cut can be undone.");
}

//-----------------------------------------------------------------------------
QString qSlicerVolumeCuttingModule::acknowledgementText() const
{
  return tr("Built on the multivolume cutting scheme of Pflesser et al., Computer Aided Surgery 7(2), 2002.");
}

//-----------------------------------------------------------------------------
QStringList qSlicerVolumeCuttingModule::contributors() const
{
  return QStringList() << QString("VolumeCutting developers");
}

//-----------------------------------------------------------------------------
QIcon qSlicerVolumeCuttingModule::icon() const
{
  return QIcon(":/Icons/VolumeCutting.png");
}

//-----------------------------------------------------------------------------
QStringList qSlicerVolumeCuttingModule::categories() const
{
  return QStringList() << "Simulation";
}

//-----------------------------------------------------------------------------
QStringList qSlicerVolumeCuttingModule::dependencies() const
{
  return QStringList() << "Segmentations";
}

//-----------------------------------------------------------------------------
QStringList qSlicerVolumeCuttingModule::associatedNodeTypes() const
{
  return QStringList() << "vtkMRMLVolumeCutNode";
}

//-----------------------------------------------------------------------------
void qSlicerVolumeCuttingModule::setup()
{
  this->Superclass::setup();
  // 3D views show volume-cut nodes through the adaptive multivolume mapper.
  vtkMRMLThreeDViewDisplayableManagerFactory::GetInstance()->RegisterDisplayableManager("vtkMRMLVolumeCutDisplayableManager");
  vtkMRMLThreeDViewDisplayableManagerFactory::GetInstance()->RegisterDisplayableManager("vtkMRMLVolumeCutToolDisplayableManager");
  // Slice views outline and fill the cut region where they cut it.
  vtkMRMLSliceViewDisplayableManagerFactory::GetInstance()->RegisterDisplayableManager("vtkMRMLVolumeCutSliceDisplayableManager");
}

//-----------------------------------------------------------------------------
qSlicerAbstractModuleRepresentation* qSlicerVolumeCuttingModule::createWidgetRepresentation()
{
  return new qSlicerVolumeCuttingModuleWidget;
}

//-----------------------------------------------------------------------------
vtkMRMLAbstractLogic* qSlicerVolumeCuttingModule::createLogic()
{
  return vtkSlicerVolumeCuttingLogic::New();
}
