/*==============================================================================

  VolumeCutting: virtual bone drilling and volume cutting for 3D Slicer.

  Licensed under the Apache License, Version 2.0 (the "License");
  you may not use this file except in compliance with the License.
  You may obtain a copy of the License at http://www.apache.org/licenses/LICENSE-2.0

==============================================================================*/

/**
 * @class   vtkSlicerVolumeCuttingHapticSession
 * @brief   Drilling a cut node with its active tool through a haptic device.
 *
 * The thin layer between the haptic loop (vtkHapticLoop, its own thread)
 * and the scene. Start builds the force model from the cut node (the CT
 * and its surface iso-value, the cut field, the active tool node's shape,
 * size and burr type), places the device's workspace where the tool is
 * (DeviceScale scene millimetres per device millimetre) and starts the
 * loop; from then on the loop (its cutter thread, see vtkHapticLoop) is the
 * cut field's only writer.
 *
 * Update, called by the application at display rate on the main thread,
 * is where the loop meets MRML: it reports device hot-plug, moves the
 * tool's transform node to the loop's latest pose (through the module
 * logic's MoveActiveTool, never from the haptic thread), invokes the cut
 * node's CutModifiedEvent when strokes were cut (views find the changed
 * bricks by their stamps) and ProtectedContactEvent when the tool went
 * deeper into a protected structure. Stop ends the loop and brings the
 * logic's tables (removed volume, contacts) up to date.
 *
 * A markups line (its first two control points) can guide the drill: a
 * virtual fixture along its axis.
 *
 * @sa vtkHapticLoop vtkHapticForceModel vtkSlicerVolumeCuttingLogic
 */

#ifndef vtkSlicerVolumeCuttingHapticSession_h
#define vtkSlicerVolumeCuttingHapticSession_h

#include "vtkSlicerVolumeCuttingModuleLogicExport.h"

// VTK includes
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkSmartPointer.h>
#include <vtkWeakPointer.h>

class vtkHapticDevice;
class vtkHapticForceModel;
class vtkHapticLoop;
class vtkMatrix4x4;
class vtkMRMLMarkupsNode;
class vtkMRMLVolumeCutNode;
class vtkSlicerVolumeCuttingLogic;

class VTK_SLICER_VOLUMECUTTING_MODULE_LOGIC_EXPORT vtkSlicerVolumeCuttingHapticSession : public vtkObject
{
public:
  static vtkSlicerVolumeCuttingHapticSession* New();
  vtkTypeMacro(vtkSlicerVolumeCuttingHapticSession, vtkObject);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The module logic whose cut fields, tools and tables the session uses (not owned).
  void SetLogic(vtkSlicerVolumeCuttingLogic* logic);
  vtkSlicerVolumeCuttingLogic* GetLogic();

  /// The loop and force model (their parameters can be changed while stopped).
  vtkHapticLoop* GetLoop();
  vtkHapticForceModel* GetForceModel();

  ///@{
  /**
   * Set/get the scene millimetres per device millimetre (the device's
   * workspace, about 40 mm for a Falcon, reaches this much farther in the
   * scene). Default is 1.
   */
  vtkSetClampMacro(DeviceScale, double, 0.01, 100.0);
  vtkGetMacro(DeviceScale, double);
  ///@}

  /**
   * Start drilling the cut node with its active tool node, moved by device
   * (opened here if it is not) and run by its buttons or, if given, the
   * foot switch's. The device's workspace centre is placed where the tool
   * is now. False, with an error saying what is missing, if the node has no
   * active tool, anatomy or cut field, or the device cannot be opened.
   */
  bool Start(vtkMRMLVolumeCutNode* cutNode, vtkHapticDevice* device, vtkHapticDevice* footSwitch = nullptr);

  /// Stop the loop (the open stroke is closed) and update the logic's tables.
  void Stop();

  bool IsRunning() const;

  /**
   * At display rate, on the main thread: device hot-plug, the tool node to
   * the loop's latest pose, the cut node's events. Returns the number of
   * strokes cut since the last call.
   */
  int Update();

  ///@{
  /**
   * Guided drilling: a virtual fixture along the axis through the first two
   * control points of a markups node (a line), in world coordinates. False
   * (and an error) without two distinct points, or while the loop runs.
   */
  bool SetGuideLine(vtkMRMLMarkupsNode* line);
  void RemoveGuide();
  ///@}

  /// The cut node the session drills (nullptr when stopped).
  vtkMRMLVolumeCutNode* GetCutNode();

protected:
  vtkSlicerVolumeCuttingHapticSession();
  ~vtkSlicerVolumeCuttingHapticSession() override;

  vtkWeakPointer<vtkSlicerVolumeCuttingLogic> Logic;
  vtkNew<vtkHapticLoop> Loop;
  vtkNew<vtkHapticForceModel> ForceModel;
  vtkNew<vtkMatrix4x4> Pose;
  vtkSmartPointer<vtkMRMLVolumeCutNode> CutNode;
  vtkSmartPointer<vtkHapticDevice> Device;
  vtkSmartPointer<vtkHapticDevice> FootSwitch;
  double DeviceScale = 1.0;
  double ReportedContactDepth = 0.0;
  /// Whether the last update saw cuts: views are told when drilling starts and stops.
  bool Drilling = false;

private:
  vtkSlicerVolumeCuttingHapticSession(const vtkSlicerVolumeCuttingHapticSession&) = delete;
  void operator=(const vtkSlicerVolumeCuttingHapticSession&) = delete;
};

#endif
