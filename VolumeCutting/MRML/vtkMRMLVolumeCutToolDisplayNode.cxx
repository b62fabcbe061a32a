/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#include "vtkMRMLVolumeCutToolDisplayNode.h"

// MRML includes
#include <vtkMRMLNodePropertyMacros.h>

// VTK includes
#include <vtkObjectFactory.h>

//----------------------------------------------------------------------------
vtkMRMLNodeNewMacro(vtkMRMLVolumeCutToolDisplayNode);

//----------------------------------------------------------------------------
vtkMRMLVolumeCutToolDisplayNode::vtkMRMLVolumeCutToolDisplayNode()
{
  // Glyph colour and visibility are user edits, undone with the tool's own.
  this->SetUndoEnabled(true);
  // Polished steel, distinct from bone and from Slicer's default model colour.
  this->SetColor(0.75, 0.78, 0.82);
}

//----------------------------------------------------------------------------
vtkMRMLVolumeCutToolDisplayNode::~vtkMRMLVolumeCutToolDisplayNode() = default;

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayNode::WriteXML(ostream& of, int nIndent)
{
  Superclass::WriteXML(of, nIndent);
  vtkMRMLWriteXMLBeginMacro(of);
  vtkMRMLWriteXMLBooleanMacro(showAxis, ShowAxis);
  vtkMRMLWriteXMLFloatMacro(glyphOpacityWhileCutting, GlyphOpacityWhileCutting);
  vtkMRMLWriteXMLEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayNode::ReadXMLAttributes(const char** atts)
{
  MRMLNodeModifyBlocker blocker(this);
  Superclass::ReadXMLAttributes(atts);
  vtkMRMLReadXMLBeginMacro(atts);
  vtkMRMLReadXMLBooleanMacro(showAxis, ShowAxis);
  vtkMRMLReadXMLFloatMacro(glyphOpacityWhileCutting, GlyphOpacityWhileCutting);
  vtkMRMLReadXMLEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayNode::CopyContent(vtkMRMLNode* anode, bool deepCopy /*=true*/)
{
  MRMLNodeModifyBlocker blocker(this);
  Superclass::CopyContent(anode, deepCopy);
  vtkMRMLCopyBeginMacro(anode);
  vtkMRMLCopyBooleanMacro(ShowAxis);
  vtkMRMLCopyFloatMacro(GlyphOpacityWhileCutting);
  vtkMRMLCopyEndMacro();
}

//----------------------------------------------------------------------------
void vtkMRMLVolumeCutToolDisplayNode::PrintSelf(ostream& os, vtkIndent indent)
{
  Superclass::PrintSelf(os, indent);
  vtkMRMLPrintBeginMacro(os, indent);
  vtkMRMLPrintBooleanMacro(ShowAxis);
  vtkMRMLPrintFloatMacro(GlyphOpacityWhileCutting);
  vtkMRMLPrintEndMacro();
}
