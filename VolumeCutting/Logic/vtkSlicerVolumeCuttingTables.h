/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

#ifndef vtkSlicerVolumeCuttingTables_h
#define vtkSlicerVolumeCuttingTables_h

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

// VTK includes
#include <vtkObject.h>

// STD includes
#include <map>
#include <string>
#include <vector>

class vtkMRMLScene;
class vtkMRMLTableNode;
class vtkMRMLVolumeCutNode;

/// \brief The tables a cut node references: removed volume per segment and contacts.
///
/// They are ordinary table nodes, so they are saved with the scene and shown
/// in Slicer's table views; the module logic decides when they change (end
/// of a stroke, undo, redo) and computes what goes in. Cells are text, as
/// Slicer's table storage writes and reads them back unchanged.
class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingTables : public vtkObject
{
public:
  static vtkSlicerVolumeCuttingTables* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingTables, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The cut node's removed-volume table (Segment, Name, Role, Removed volume
  /// in mm3), added to the scene and referenced under \a role when the node
  /// references none; \a created tells whether it was added (still empty).
  static vtkMRMLTableNode* GetRemovedVolumeTable(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role, bool& created);

  /// The cut node's contact table (Segment, Name, Time, Depth in mm, R, A,
  /// S), added and referenced under \a role when the node references none.
  static vtkMRMLTableNode* GetContactTable(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role);

#ifndef __VTK_WRAP__
  /// Replace the rows of a removed-volume table: one per segment, with its
  /// role in the cut node and its removed volume (0 where \a volumes has none).
  static void FillRemovedVolumeTable(vtkMRMLTableNode* table, vtkMRMLVolumeCutNode* cutNode, const std::vector<std::string>& segmentIds,
                                     const std::map<std::string, double>& volumes);
#endif

  /// Add a row to a contact table: the segment touched (ID, and its name in
  /// the cut node's segmentation), now in UTC, the depth (mm) and position (RAS).
  static void AddContact(vtkMRMLTableNode* table, vtkMRMLVolumeCutNode* cutNode, const std::string& segmentId, double depth, const double position[3]);
  /// The cut node's nerve-monitor table (Time in s, Segment, Name, Distance
  /// in mm, Level), added and referenced under \a role when the node references none.
  static vtkMRMLTableNode* GetNerveMonitorTable(vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role);
  /// Add a row to a nerve-monitor table: a reading of one monitored segment.
  static void AddNerveReading(
    vtkMRMLTableNode* table, double time, const std::string& segmentId, const std::string& name, double distance, const char* level);

protected:
  vtkSlicerVolumeCuttingTables();
  ~vtkSlicerVolumeCuttingTables() override;

  /// The table the cut node references under a role, or a new one with text
  /// columns, named after the node, when it references no table there.
  static vtkMRMLTableNode* GetReferencedTable(
    vtkMRMLScene* scene, vtkMRMLVolumeCutNode* cutNode, const char* role, const char* nameSuffix, const std::vector<std::string>& columns);

private:
  vtkSlicerVolumeCuttingTables(const vtkSlicerVolumeCuttingTables&) = delete;
  void operator=(const vtkSlicerVolumeCuttingTables&) = delete;
};

#endif
