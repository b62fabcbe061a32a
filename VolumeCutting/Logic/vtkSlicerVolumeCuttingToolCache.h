/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkSlicerVolumeCuttingToolCache_h
#define vtkSlicerVolumeCuttingToolCache_h

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

// VTK includes
#include <vtkObject.h>
#include <vtkSmartPointer.h>

// STD includes
#include <map>
#include <string>
#include <utility>

class vtkMRMLVolumeCutToolNode;
class vtkVolumeCutTool;

/// \brief The cutting tool (vtkVolumeCutTool) each tool node describes.
///
/// A stroke of the active tool sweeps its shape once per pose, a thousand
/// poses a second from a haptic device: the tool (for a mesh tool, its
/// distance structure) is built once per change of the tool node or of its
/// mesh model's surface, not per pose.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingToolCache : public vtkObject
{
public:
  static vtkSlicerVolumeCuttingToolCache* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingToolCache, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The cutting tool a non-spherical tool node describes (a disk saw is a
  /// cylinder as long as its blade is thick, a blade a box), rebuilt when the
  /// node or its mesh changed. nullptr for a spherical burr (it sweeps as a
  /// capsule, without a tool), and with an error for a mesh tool without a
  /// surface or sizes that do not describe a valid tool.
  vtkVolumeCutTool* GetTool(vtkMRMLVolumeCutToolNode* toolNode);

  /// Drop the tool built for a node (removed from the scene), or all of them.
  void Forget(const std::string& toolNodeId);
  void ForgetAll();

protected:
  vtkSlicerVolumeCuttingToolCache();
  ~vtkSlicerVolumeCuttingToolCache() override;

  /// Cutting tools by tool-node ID, with the modification time they match.
  std::map<std::string, std::pair<vtkMTimeType, vtkSmartPointer<vtkVolumeCutTool>>> Tools;

private:
  vtkSlicerVolumeCuttingToolCache(const vtkSlicerVolumeCuttingToolCache&) = delete;
  void operator=(const vtkSlicerVolumeCuttingToolCache&) = delete;
};

#endif
