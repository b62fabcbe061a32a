/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkMRMLVolumeCutToolDisplayNode_h
#define vtkMRMLVolumeCutToolDisplayNode_h

// MRML includes
#include <vtkMRMLDisplayNode.h>

#include "vtkSlicerVolumeCuttingModuleMRMLExport.h"

/// \brief How the views draw a cutting tool's glyph.
///
/// Colour, opacity and visibility come from vtkMRMLDisplayNode. The glyph is
/// the tool's cutting part (burr, disk, blade or mesh) at its pose; this node
/// adds the shaft axis and a second opacity used while the tool cuts, so that
/// the surgeon sees the bone being removed under the burr.
///
/// \sa vtkMRMLVolumeCutToolNode
class VTK_SLICER_VOLUMECUTTING_MODULE_MRML_EXPORT vtkMRMLVolumeCutToolDisplayNode : public vtkMRMLDisplayNode
{
public:
  static vtkMRMLVolumeCutToolDisplayNode* New();
  vtkTypeMacro(vtkMRMLVolumeCutToolDisplayNode, vtkMRMLDisplayNode);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  vtkMRMLNode* CreateNodeInstance() override;
  const char* GetNodeTagName() override { return "VolumeCutToolDisplay"; }

  void ReadXMLAttributes(const char** atts) override;
  void WriteXML(ostream& of, int indent) override;
  vtkMRMLCopyContentMacro(vtkMRMLVolumeCutToolDisplayNode);

  ///@{
  /// Whether the shaft axis (the tool's local z axis, towards the handpiece)
  /// is drawn with the glyph: it shows the drilling direction, which the
  /// round burr alone does not. Default is true.
  vtkGetMacro(ShowAxis, bool);
  vtkSetMacro(ShowAxis, bool);
  vtkBooleanMacro(ShowAxis, bool);
  ///@}

  ///@{
  /// Opacity (0 to 1) of the glyph while the tool is cutting, in place of
  /// Opacity, so that the cut surface under the burr stays visible.
  /// Default is 0.3.
  vtkGetMacro(GlyphOpacityWhileCutting, double);
  vtkSetClampMacro(GlyphOpacityWhileCutting, double, 0.0, 1.0);
  ///@}

protected:
  vtkMRMLVolumeCutToolDisplayNode();
  ~vtkMRMLVolumeCutToolDisplayNode() override;
  vtkMRMLVolumeCutToolDisplayNode(const vtkMRMLVolumeCutToolDisplayNode&) = delete;
  void operator=(const vtkMRMLVolumeCutToolDisplayNode&) = delete;

  bool ShowAxis{ true };
  double GlyphOpacityWhileCutting{ 0.3 };
};

#endif
