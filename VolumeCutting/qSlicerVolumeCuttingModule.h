/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef __qSlicerVolumeCuttingModule_h
#define __qSlicerVolumeCuttingModule_h

// Slicer includes
#include "qSlicerLoadableModule.h"

#include "qSlicerVolumeCuttingModuleExport.h"

class qSlicerVolumeCuttingModulePrivate;

/// Desktop entry point of the VolumeCutting loadable module. It only wires the
/// logic and the widget into the application: everything testable lives in
/// vtkSlicerVolumeCuttingLogic and the libraries below it.
class Q_SLICER_QTMODULES_VOLUMECUTTING_EXPORT qSlicerVolumeCuttingModule : public qSlicerLoadableModule
{
  Q_OBJECT
  Q_PLUGIN_METADATA(IID "org.slicer.modules.loadable.qSlicerLoadableModule/1.0");
  Q_INTERFACES(qSlicerLoadableModule);

public:
  typedef qSlicerLoadableModule Superclass;
  explicit qSlicerVolumeCuttingModule(QObject* parent = nullptr);
  ~qSlicerVolumeCuttingModule() override;

  qSlicerGetTitleMacro(QTMODULE_TITLE);

  QString helpText() const override;
  QString acknowledgementText() const override;
  QStringList contributors() const override;
  QIcon icon() const override;
  QStringList categories() const override;
  QStringList dependencies() const override;
  QStringList associatedNodeTypes() const override;

protected:
  void setup() override;
  qSlicerAbstractModuleRepresentation* createWidgetRepresentation() override;
  vtkMRMLAbstractLogic* createLogic() override;

protected:
  QScopedPointer<qSlicerVolumeCuttingModulePrivate> d_ptr;

private:
  Q_DECLARE_PRIVATE(qSlicerVolumeCuttingModule);
  Q_DISABLE_COPY(qSlicerVolumeCuttingModule);
};

#endif
