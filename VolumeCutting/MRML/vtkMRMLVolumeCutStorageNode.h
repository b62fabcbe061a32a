/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkMRMLVolumeCutStorageNode_h
#define vtkMRMLVolumeCutStorageNode_h

// MRML includes
#include <vtkMRMLStorageNode.h>

#include "vtkSlicerVolumeCuttingModuleMRMLExport.h"

/// \brief Saves and reads the cut field of a vtkMRMLVolumeCutNode (.vcut).
///
/// The file holds the field's geometry and its allocated bricks (see
/// vtkVolumeCutField::WriteFile), so a saved scene reopens with every cut.
/// A corrupt or foreign file is refused with an error and the node keeps
/// the field it had.
class VTK_SLICER_VOLUMECUTTING_MODULE_MRML_EXPORT vtkMRMLVolumeCutStorageNode : public vtkMRMLStorageNode
{
public:
  static vtkMRMLVolumeCutStorageNode* New();
  vtkTypeMacro(vtkMRMLVolumeCutStorageNode, vtkMRMLStorageNode);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkMRMLNode* CreateNodeInstance() override;
  const char* GetNodeTagName() override { return "VolumeCutStorage"; }

  bool CanReadInReferenceNode(vtkMRMLNode* refNode) override;

protected:
  vtkMRMLVolumeCutStorageNode();
  ~vtkMRMLVolumeCutStorageNode() override;
  vtkMRMLVolumeCutStorageNode(const vtkMRMLVolumeCutStorageNode&) = delete;
  void operator=(const vtkMRMLVolumeCutStorageNode&) = delete;

  void InitializeSupportedReadFileTypes() override;
  void InitializeSupportedWriteFileTypes() override;
  int ReadDataInternal(vtkMRMLNode* refNode) override;
  int WriteDataInternal(vtkMRMLNode* refNode) override;
};

#endif
