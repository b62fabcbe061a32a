/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkMRMLVolumeCutStorageNode.h"
#include "vtkMRMLVolumeCutNode.h"

// VolumeCutting includes
#include <vtkVolumeCutField.h>

// VTK includes
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkStringArray.h>

//----------------------------------------------------------------------------
vtkMRMLNodeNewMacro(vtkMRMLVolumeCutStorageNode);

//----------------------------------------------------------------------------
vtkMRMLVolumeCutStorageNode::vtkMRMLVolumeCutStorageNode()
{
  this->DefaultWriteFileExtension = "vcut";
}

//----------------------------------------------------------------------------
vtkMRMLVolumeCutStorageNode::~vtkMRMLVolumeCutStorageNode() = default;

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutStorageNode::PrintSelf(ostream& os, vtkIndent indent)
{
  Superclass::PrintSelf(os, indent);
}

//----------------------------------------------------------------------------
bool vtkMRMLVolumeCutStorageNode::CanReadInReferenceNode(vtkMRMLNode* refNode)
{
  return refNode && refNode->IsA("vtkMRMLVolumeCutNode");
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutStorageNode::InitializeSupportedReadFileTypes()
{
  this->SupportedReadFileTypes->InsertNextValue("Volume cut field (.vcut)");
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutStorageNode::InitializeSupportedWriteFileTypes()
{
  this->SupportedWriteFileTypes->InsertNextValue("Volume cut field (.vcut)");
}

//----------------------------------------------------------------------------
int vtkMRMLVolumeCutStorageNode::ReadDataInternal(vtkMRMLNode* refNode)
{
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(refNode);
  if (!cutNode)
  {
    vtkErrorMacro("ReadDataInternal: not a volume-cut node");
    return 0;
  }
  const std::string fileName = this->GetFullNameFromFileName();
  vtkNew<vtkVolumeCutField> field;
  if (!field->ReadFile(fileName.c_str()))
  {
    vtkErrorMacro("ReadDataInternal: could not read the cut field of '" << (cutNode->GetName() ? cutNode->GetName() : "") << "' from " << fileName);
    return 0;
  }
  cutNode->SetCutField(field->GetDimensions()[0] > 0 ? field.GetPointer() : nullptr);
  return 1;
}

//----------------------------------------------------------------------------
int vtkMRMLVolumeCutStorageNode::WriteDataInternal(vtkMRMLNode* refNode)
{
  vtkMRMLVolumeCutNode* cutNode = vtkMRMLVolumeCutNode::SafeDownCast(refNode);
  if (!cutNode)
  {
    vtkErrorMacro("WriteDataInternal: not a volume-cut node");
    return 0;
  }
  const std::string fileName = this->GetFullNameFromFileName();
  // A node that has not cut yet is saved as an empty field, so that reading
  // the scene finds its file.
  vtkNew<vtkVolumeCutField> empty;
  vtkVolumeCutField* field = cutNode->GetCutField() ? cutNode->GetCutField() : empty.GetPointer();
  return field->WriteFile(fileName.c_str()) ? 1 : 0;
}
