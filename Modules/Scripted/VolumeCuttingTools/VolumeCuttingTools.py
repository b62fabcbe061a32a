"""VolumeCuttingTools: the Python side of VolumeCutting in desktop Slicer.

Thin by design: the widget only connects the GUI to VolumeCuttingToolsLogic, and
the logic forwards to VolumeCuttingLib (Qt-free, tested with pytest against
slicer-core) and to the C++ vtkSlicerVolumeCuttingLogic. Tool configuration
(presets, shape, burr type, sizes, drive, per-segment sensibility, input
device) is VolumeCuttingLib.config.toolconfig; this file only shows it.
"""

import logging
import tempfile
from pathlib import Path
from typing import Annotated

import qt
import slicer
import vtk
from slicer.parameterNodeWrapper import Choice, WithinRange, parameterNodeWrapper
from slicer.ScriptedLoadableModule import (
    ScriptedLoadableModule,
    ScriptedLoadableModuleLogic,
    ScriptedLoadableModuleTest,
    ScriptedLoadableModuleWidget,
)
from slicer.util import VTKObservationMixin

from VolumeCuttingLib.collaboration import desktopcoupling
from VolumeCuttingLib.config import hapticdrilling, inputdevices, toolconfig
from VolumeCuttingLib.data import headct, phantom
from VolumeCuttingLib.feedback import desktopfeedback
from VolumeCuttingLib.jobs import selftests

# Read once: the parameter node's choices are fixed when the module loads.
TOOL_PRESETS = {preset.name: preset for preset in toolconfig.load_presets()}
DEFAULT_TOOL = toolconfig.ToolParameters()
# The widest diameter range (burrs to disk saws); toolconfig checks the shape's own.
DIAMETER_LIMITS = (toolconfig.diameter_range("Sphere")[0], toolconfig.diameter_range("DiskSaw")[1])


#
# VolumeCuttingTools
#


class VolumeCuttingTools(ScriptedLoadableModule):
    def __init__(self, parent):
        ScriptedLoadableModule.__init__(self, parent)
        self.parent.title = "Volume Cutting Tools"
        self.parent.categories = ["Simulation"]
        self.parent.dependencies = ["VolumeCutting"]
        self.parent.contributors = ["VolumeCutting developers"]
        self.parent.helpText = (
            "Data and tool configuration for virtual bone drilling: load the example head CT or a "
            "procedural temporal-bone phantom with analytic geometry, and prepare a cut session."
        )
        self.parent.acknowledgementText = "Head CT: Debian package invesalius-examples (CTI Renato Archer, GPL-2)."


#
# VolumeCuttingToolsParameterNode
#


@parameterNodeWrapper
class VolumeCuttingToolsParameterNode:
    """
    The parameters needed by the module.

    phantomSize - voxels along each axis of a generated phantom.
    phantomSpacing - isotropic voxel size of a generated phantom in mm.
    phantomSeed - noise seed; the same seed gives the same phantom.
    anatomyVolume - the CT the cut session works on.
    segmentation - its segmentation.
    cutNode - the volume-cut session whose segment roles the tools follow.
    toolNode - the cutting tool being configured.
    toolPreset - the preset "Load preset" copies into the fields below.
    toolShape, burrType - shape of the tool and kind of burr.
    toolDiameter, toolLength, toolThickness, toolWidth - sizes in mm (which ones a shape uses: toolconfig.SHAPE_FIELDS).
    toolPower - fraction of the handpiece's maximum power.
    toolSpeed - revolutions (burrs, disk saws) or oscillations (blades) per minute.
    inputDevice - device_id of the device that drives the tool (toolconfig.list_devices()).
    couplingRole - the instructor coupling's side: off, trainee (waits) or instructor (connects).
    couplingPort - the UDP port the trainee's side waits on (0: any free port, shown once started).
    couplingFromOtherMachines - the trainee's side can be reached from other machines (else this one only).
    couplingPeer - HOST:PORT of the trainee's side the instructor's connects to.
    """

    phantomSize: Annotated[int, WithinRange(32, 256)] = 128
    phantomSpacing: Annotated[float, WithinRange(0.1, 2.0)] = 0.4
    phantomSeed: Annotated[int, WithinRange(0, 2**31 - 1)] = 0
    anatomyVolume: slicer.vtkMRMLScalarVolumeNode
    segmentation: slicer.vtkMRMLSegmentationNode
    cutNode: slicer.vtkMRMLVolumeCutNode
    toolNode: slicer.vtkMRMLVolumeCutToolNode
    toolPreset: Annotated[str, Choice(list(TOOL_PRESETS))] = next(iter(TOOL_PRESETS))
    toolShape: Annotated[str, Choice(list(toolconfig.SHAPES))] = DEFAULT_TOOL.shape
    burrType: Annotated[str, Choice(list(toolconfig.BURR_TYPES))] = DEFAULT_TOOL.burr_type
    toolDiameter: Annotated[float, WithinRange(*DIAMETER_LIMITS)] = DEFAULT_TOOL.diameter
    toolLength: Annotated[float, WithinRange(*toolconfig.RANGES["length"])] = DEFAULT_TOOL.length
    toolThickness: Annotated[float, WithinRange(*toolconfig.RANGES["thickness"])] = DEFAULT_TOOL.thickness
    toolWidth: Annotated[float, WithinRange(*toolconfig.RANGES["width"])] = DEFAULT_TOOL.width
    toolPower: Annotated[float, WithinRange(*toolconfig.RANGES["power"])] = DEFAULT_TOOL.power
    toolSpeed: Annotated[float, WithinRange(*toolconfig.RANGES["speed"])] = DEFAULT_TOOL.speed
    inputDevice: str = "mouse"
    couplingRole: Annotated[str, Choice(list(desktopcoupling.ROLES))] = desktopcoupling.OFF
    couplingPort: Annotated[int, WithinRange(0, 65535)] = 47000
    couplingFromOtherMachines: bool = False
    couplingPeer: str = "127.0.0.1:47000"


#
# VolumeCuttingToolsWidget
#


class VolumeCuttingToolsWidget(ScriptedLoadableModuleWidget, VTKObservationMixin):
    def __init__(self, parent=None) -> None:
        ScriptedLoadableModuleWidget.__init__(self, parent)
        VTKObservationMixin.__init__(self)
        self.logic = None
        self._parameterNode = None
        self._parameterNodeGuiTag = None
        self._drilling = None
        self._drillTimer = None
        self._feedback = None
        self._coupling = desktopcoupling.DesktopCoupling()
        self._couplingTimer = None

    def setup(self) -> None:
        ScriptedLoadableModuleWidget.setup(self)
        uiWidget = slicer.util.loadUI(self.resourcePath("UI/VolumeCuttingTools.ui"))
        self.layout.addWidget(uiWidget)
        self.ui = slicer.util.childWidgetVariables(uiWidget)
        uiWidget.setMRMLScene(slicer.mrmlScene)
        self.logic = VolumeCuttingToolsLogic()

        self.addObserver(slicer.mrmlScene, slicer.mrmlScene.StartCloseEvent, self.onSceneStartClose)
        self.addObserver(slicer.mrmlScene, slicer.mrmlScene.EndCloseEvent, self.onSceneEndClose)
        self.ui.loadHeadCTButton.connect("clicked(bool)", self.onLoadHeadCT)
        self.ui.generatePhantomButton.connect("clicked(bool)", self.onGeneratePhantom)
        self.ui.loadPresetButton.connect("clicked(bool)", self.onLoadPreset)
        self.ui.createToolButton.connect("clicked(bool)", self.onCreateTool)
        self.ui.applyToolButton.connect("clicked(bool)", self.onApplyTool)
        self.ui.followRolesButton.connect("clicked(bool)", self.onFollowCutNodeRoles)
        self.ui.sensibilityTable.connect("itemChanged(QTableWidgetItem*)", self.onSensibilityItemChanged)
        self.ui.refreshDevicesButton.connect("clicked(bool)", self.onRefreshDevices)
        self.ui.inputDeviceComboBox.connect("currentIndexChanged(int)", self.onInputDeviceChanged)
        self.ui.drillButton.connect("toggled(bool)", self.onDrillToggled)
        self.ui.drillSoundCheckBox.connect("toggled(bool)", self.onDrillSoundToggled)
        self.ui.soundVolumeSliderWidget.connect("valueChanged(double)", self.onSoundVolumeChanged)
        for radio in self._couplingRadios().values():
            radio.connect("toggled(bool)", self.onCouplingRoleToggled)
        self.ui.couplingButton.connect("toggled(bool)", self.onCouplingToggled)
        # The status line follows the coupling (the peer joining, going, refused) on a timer of its own: the
        # instructor's side runs without the Drill's.
        self._couplingTimer = qt.QTimer()
        self._couplingTimer.setInterval(round(desktopcoupling.STATUS_PERIOD_S * 1000))
        self._couplingTimer.connect("timeout()", self.onCouplingTimer)
        # The scene follows the haptic thread at display rate; the monitor's meter and the drill sound's
        # parameters follow at the same rate (at least the 50 Hz the sound needs).
        self._drillTimer = qt.QTimer()
        self._drillTimer.setInterval(round(desktopfeedback.TICK_PERIOD_S * 1000))
        self._drillTimer.connect("timeout()", self.onDrillTimer)
        self.onRefreshDevices()
        self.initializeParameterNode()

    def cleanup(self) -> None:
        self._stopDrilling()
        self._stopCoupling()
        self.removeObservers()

    def enter(self) -> None:
        self.initializeParameterNode()

    def exit(self) -> None:
        if self._parameterNode:
            self._parameterNode.disconnectGui(self._parameterNodeGuiTag)
            self._parameterNodeGuiTag = None
            self.removeObserver(self._parameterNode, vtk.vtkCommand.ModifiedEvent, self._onParameterNodeModified)

    def onSceneStartClose(self, caller, event) -> None:
        self._stopDrilling()
        self._stopCoupling()
        self.setParameterNode(None)

    def onSceneEndClose(self, caller, event) -> None:
        if self.parent.isEntered:
            self.initializeParameterNode()

    def initializeParameterNode(self) -> None:
        self.setParameterNode(self.logic.getParameterNode())
        # Select default nodes if nothing is selected yet.
        if not self._parameterNode.cutNode:
            self._parameterNode.cutNode = slicer.mrmlScene.GetFirstNodeByClass("vtkMRMLVolumeCutNode")
        if not self._parameterNode.toolNode:
            self._parameterNode.toolNode = slicer.mrmlScene.GetFirstNodeByClass("vtkMRMLVolumeCutToolNode")

    def setParameterNode(self, inputParameterNode) -> None:
        if self._parameterNode:
            self._parameterNode.disconnectGui(self._parameterNodeGuiTag)
            self.removeObserver(self._parameterNode, vtk.vtkCommand.ModifiedEvent, self._onParameterNodeModified)
        self._parameterNode = inputParameterNode
        if self._parameterNode:
            self._parameterNodeGuiTag = self._parameterNode.connectGui(self.ui)
            self.addObserver(self._parameterNode, vtk.vtkCommand.ModifiedEvent, self._onParameterNodeModified)
            self._onParameterNodeModified()
            self._selectInputDevice()

    def _onParameterNodeModified(self, caller=None, event=None) -> None:
        p = self._parameterNode
        self.ui.applyToolButton.enabled = p is not None and p.toolNode is not None
        self.ui.followRolesButton.enabled = p is not None and p.toolNode is not None
        if p is not None:
            radio = self._couplingRadios()[p.couplingRole]
            wasBlocked = radio.blockSignals(True)
            radio.checked = True
            radio.blockSignals(wasBlocked)
        self._updateSensibilityTable()

    def _updateSensibilityTable(self) -> None:
        p = self._parameterNode
        rows = self.logic.sensibilityRows(p.cutNode, p.toolNode) if p else []
        table = self.ui.sensibilityTable
        wasBlocked = table.blockSignals(True)
        table.setRowCount(len(rows))
        for index, row in enumerate(rows):
            nameItem = qt.QTableWidgetItem(row.name)
            nameItem.setData(qt.Qt.UserRole, row.segment_id)
            nameItem.setData(qt.Qt.DecorationRole, qt.QColor.fromRgbF(*row.color))
            nameItem.setFlags(qt.Qt.ItemIsEnabled)
            roleItem = qt.QTableWidgetItem(row.role or "-")
            roleItem.setFlags(qt.Qt.ItemIsEnabled)
            cutItem = qt.QTableWidgetItem("from tool" if row.from_tool else "from roles")
            cutItem.setFlags(qt.Qt.ItemIsEnabled | qt.Qt.ItemIsUserCheckable if row.editable and p.toolNode else qt.Qt.ItemIsEnabled)
            cutItem.setCheckState(qt.Qt.Checked if row.may_cut else qt.Qt.Unchecked)
            for column, item in enumerate((nameItem, roleItem, cutItem)):
                table.setItem(index, column, item)
        table.blockSignals(wasBlocked)

    def onLoadHeadCT(self) -> None:
        with slicer.util.tryWithErrorDisplay("Failed to load the head CT.", waitCursor=True):
            volume = self.logic.loadHeadCT()
            self._parameterNode.anatomyVolume = volume

    def onGeneratePhantom(self) -> None:
        with slicer.util.tryWithErrorDisplay("Failed to generate the phantom.", waitCursor=True):
            p = self._parameterNode
            volume, segmentation = self.logic.generatePhantom(p.phantomSize, p.phantomSpacing, p.phantomSeed)
            p.anatomyVolume = volume
            p.segmentation = segmentation

    def onLoadPreset(self) -> None:
        with slicer.util.tryWithErrorDisplay("Failed to load the tool preset."):
            self.logic.loadPreset(self._parameterNode)

    def onCreateTool(self) -> None:
        with slicer.util.tryWithErrorDisplay("Failed to create the tool."):
            self._parameterNode.toolNode = self.logic.createTool(self._parameterNode)

    def onApplyTool(self) -> None:
        with slicer.util.tryWithErrorDisplay("Failed to configure the tool."):
            self.logic.applyToTool(self._parameterNode)

    def onFollowCutNodeRoles(self) -> None:
        self._parameterNode.toolNode.SetUseCutNodeRoles(True)
        self._updateSensibilityTable()

    def onSensibilityItemChanged(self, item) -> None:
        p = self._parameterNode
        if item.column() != 2 or not p.toolNode:
            return
        segmentId = self.ui.sensibilityTable.item(item.row(), 0).data(qt.Qt.UserRole)
        with slicer.util.tryWithErrorDisplay("Failed to change what the tool may cut."):
            self.logic.setSegmentCuttableForTool(p.cutNode, p.toolNode, segmentId, item.checkState() == qt.Qt.Checked)
        self._updateSensibilityTable()

    def onRefreshDevices(self) -> None:
        combo = self.ui.inputDeviceComboBox
        wasBlocked = combo.blockSignals(True)
        combo.clear()
        footSwitches = self.ui.footSwitchComboBox
        footSwitches.clear()
        footSwitches.addItem("None", "")
        for device in self.logic.listDevices():
            combo.addItem(device.label, device.device_id)
            if device.kind == inputdevices.FOOT_SWITCH:
                footSwitches.addItem(device.label, device.device_id)
        combo.blockSignals(wasBlocked)
        self._selectInputDevice()

    def _selectInputDevice(self) -> None:
        """Show the parameter node's device; one no longer plugged in falls back to the mouse."""
        if self._parameterNode:
            combo = self.ui.inputDeviceComboBox
            combo.setCurrentIndex(max(combo.findData(self._parameterNode.inputDevice), 0))

    def onInputDeviceChanged(self, index: int) -> None:
        if self._parameterNode and index >= 0:
            self._parameterNode.inputDevice = self.ui.inputDeviceComboBox.itemData(index)

    def onDrillToggled(self, checked: bool) -> None:
        if not checked:
            self._stopDrilling()
            return
        view = slicer.app.layoutManager().threeDWidget(0).threeDView()
        renderer = view.renderWindow().GetRenderers().GetFirstRenderer()
        try:
            refusal = self._coupling.refuses_drill()
            if refusal:
                raise hapticdrilling.HapticDrillingError(refusal)
            self._drilling = self.logic.startDrilling(
                self._parameterNode, renderer, view.interactor(),
                footSwitch=self.ui.footSwitchComboBox.currentData or None,
                falconFirmware=self.ui.falconFirmwarePathLineEdit.currentPath or None)
        except hapticdrilling.HapticDrillingError as error:
            slicer.util.errorDisplay(f"Drilling could not start: {error}")
            wasBlocked = self.ui.drillButton.blockSignals(True)
            self.ui.drillButton.checked = False
            self.ui.drillButton.blockSignals(wasBlocked)
            return
        self._feedback = self.logic.startFeedback(
            self._parameterNode, sound=self.ui.drillSoundCheckBox.checked, volume=self.ui.soundVolumeSliderWidget.value)
        self.ui.soundStatusLabel.text = self._feedback.message
        self._drillTimer.start()

    def onDrillTimer(self) -> None:
        if self._drilling is not None:
            self._drilling.update()
            if self._feedback is not None:
                rows = self._feedback.tick(self._drilling.drilling)
                if self._feedback.rows_changed:
                    self._showMonitorRows(rows)

    def onDrillSoundToggled(self, checked: bool) -> None:
        if self._feedback is not None:
            self._feedback.set_sound(checked)
            self.ui.soundStatusLabel.text = self._feedback.message

    def onSoundVolumeChanged(self, volume: float) -> None:
        if self._feedback is not None:
            self._feedback.set_volume(volume)

    def _showMonitorRows(self, rows) -> None:
        """The meter: per structure its name, a distance bar (0-8 mm) and the level, in the level's colour."""
        table = self.ui.monitorTable
        table.setRowCount(len(rows))
        for index, row in enumerate(rows):
            nameItem = qt.QTableWidgetItem(row["name"])
            table.setItem(index, 0, nameItem)
            bar = table.cellWidget(index, 1)
            if bar is None:
                bar = qt.QProgressBar()
                bar.setRange(0, 1000)
                table.setCellWidget(index, 1, bar)
            bar.setValue(round(row["bar"] * 1000))
            bar.setFormat("not ready" if row["mm"] is None else f"{row['mm']:.2f} mm")
            bar.setStyleSheet(f"QProgressBar::chunk {{ background-color: {row['colour']}; }}")
            levelItem = qt.QTableWidgetItem(row["level"])
            levelItem.setBackground(qt.QBrush(qt.QColor(row["colour"])))
            table.setItem(index, 2, levelItem)

    def _couplingRadios(self) -> dict:
        return {desktopcoupling.OFF: self.ui.couplingOffRadioButton, desktopcoupling.TRAINEE: self.ui.couplingTraineeRadioButton,
                desktopcoupling.INSTRUCTOR: self.ui.couplingInstructorRadioButton}

    def onCouplingRoleToggled(self, checked: bool) -> None:
        if checked and self._parameterNode:
            self._parameterNode.couplingRole = next(role for role, radio in self._couplingRadios().items() if radio.checked)

    def onCouplingToggled(self, checked: bool) -> None:
        if not checked:
            self._stopCoupling()
            return
        p = self._parameterNode
        view = slicer.app.layoutManager().threeDWidget(0).threeDView()
        try:
            snapshot = self._coupling.start(
                p.couplingRole, port=p.couplingPort, peer=p.couplingPeer, from_other_machines=p.couplingFromOtherMachines,
                drilling=self._drilling, volume=self.logic.couplingVolume(p), device=p.inputDevice,
                renderer=view.renderWindow().GetRenderers().GetFirstRenderer(), interactor=view.interactor(),
                falcon_firmware=self.ui.falconFirmwarePathLineEdit.currentPath or None, tool_node=p.toolNode)
        except desktopcoupling.CouplingInputError as error:
            self._showCoupling(self._coupling.status())
            self.ui.couplingStatusLabel.text = f"Not started: {error}."
            return
        self._showCoupling(snapshot)
        self._couplingTimer.start()

    def onCouplingTimer(self) -> None:
        self._showCoupling(self._coupling.status())

    def _showCoupling(self, snapshot) -> None:
        """The status line, the button and the fields (locked while the coupling runs)."""
        self.ui.couplingStatusLabel.text = snapshot.text
        if not snapshot.running and self._couplingTimer is not None:
            self._couplingTimer.stop()
        wasBlocked = self.ui.couplingButton.blockSignals(True)
        self.ui.couplingButton.checked = snapshot.running
        self.ui.couplingButton.text = "Stop coupling" if snapshot.running else "Start coupling"
        self.ui.couplingButton.blockSignals(wasBlocked)
        for widget in (*self._couplingRadios().values(), self.ui.couplingPortSpinBox, self.ui.couplingPeerLineEdit,
                       self.ui.couplingFromOtherMachinesCheckBox):
            widget.enabled = not snapshot.running

    def _stopCoupling(self) -> None:
        """Stop this side (the trainee's Drill goes on uncoupled, every cut kept)."""
        if hasattr(self, "ui"):
            self._showCoupling(self._coupling.stop())
        else:
            self._coupling.stop()

    def _stopDrilling(self) -> None:
        if self._drillTimer is not None:
            self._drillTimer.stop()
        if self._feedback is not None:
            self._feedback.stop()
            self._feedback = None
            self._showMonitorRows([])
        if self._drilling is not None:
            self._drilling.stop()
            self._drilling = None
        if hasattr(self, "ui") and self.ui.drillButton.checked:
            wasBlocked = self.ui.drillButton.blockSignals(True)
            self.ui.drillButton.checked = False
            self.ui.drillButton.blockSignals(wasBlocked)


#
# VolumeCuttingToolsLogic
#


class VolumeCuttingToolsLogic(ScriptedLoadableModuleLogic):
    """Desktop wrapper of VolumeCuttingLib; runs without the widget (and is tested without it)."""

    def getParameterNode(self):
        return VolumeCuttingToolsParameterNode(super().getParameterNode())

    def loadHeadCT(self) -> vtk.vtkObject:
        volume = headct.load_volume_node(slicer.mrmlScene, name="HeadCT")
        slicer.util.setSliceViewerLayers(background=volume, fit=True)
        return volume

    def generatePhantom(self, size: int, spacing: float, seed: int):
        logging.info(f"Generating a {size}^3 temporal-bone phantom at {spacing} mm, seed {seed}")
        generated = phantom.generate_phantom(dimensions=(size, size, size), spacing=(spacing, spacing, spacing), seed=seed)
        volume, segmentation = phantom.create_phantom_nodes(slicer.mrmlScene, generated)
        slicer.util.setSliceViewerLayers(background=volume, fit=True)
        return volume, segmentation

    def toolParameters(self, parameterNode, baseline=None) -> toolconfig.ToolParameters:
        """The parameter node's tool fields over ``baseline`` (sensibility and mesh are kept from it)."""
        p = parameterNode
        return (baseline or toolconfig.ToolParameters()).replace(
            shape=p.toolShape, burr_type=p.burrType, diameter=p.toolDiameter, length=p.toolLength,
            thickness=p.toolThickness, width=p.toolWidth, power=p.toolPower, speed=p.toolSpeed)

    def loadPreset(self, parameterNode) -> None:
        tool = toolconfig.from_preset(TOOL_PRESETS[parameterNode.toolPreset])
        with slicer.util.NodeModify(parameterNode):
            parameterNode.toolShape = tool.shape
            parameterNode.burrType = tool.burr_type
            parameterNode.toolDiameter = tool.diameter
            parameterNode.toolLength = tool.length
            parameterNode.toolThickness = tool.thickness
            parameterNode.toolWidth = tool.width
            parameterNode.toolPower = tool.power
            parameterNode.toolSpeed = tool.speed

    def createTool(self, parameterNode):
        return toolconfig.create_tool_node(slicer.mrmlScene, self.toolParameters(parameterNode), parameterNode.toolPreset)

    def applyToTool(self, parameterNode) -> None:
        tool = parameterNode.toolNode
        toolconfig.apply_to_tool_node(self.toolParameters(parameterNode, toolconfig.from_tool_node(tool)), tool)

    def sensibilityRows(self, cutNode, toolNode):
        return toolconfig.sensibility_rows(cutNode, toolNode)

    def setSegmentCuttableForTool(self, cutNode, toolNode, segmentId: str, cuttable: bool) -> None:
        toolconfig.set_segment_cuttable_for_tool(cutNode, toolNode, segmentId, cuttable)

    def listDevices(self):
        return toolconfig.list_devices()

    def startDrilling(self, parameterNode, renderer, interactor, footSwitch=None, falconFirmware=None):
        """Drill the parameter node's cut session with its input device; the running HapticDrilling (raises HapticDrillingError)."""
        drilling = hapticdrilling.HapticDrilling(slicer.modules.volumecutting.logic())
        drilling.start(parameterNode.cutNode, parameterNode.inputDevice, renderer, interactor,
                       foot_switch=footSwitch, falcon_firmware=falconFirmware)
        return drilling

    def couplingVolume(self, parameterNode):
        """The scan both sides of the instructor coupling must load: the cut session's CT, else the chosen CT."""
        p = parameterNode
        cutVolume = p.cutNode.GetAnatomyVolumeNode() if p.cutNode is not None else None
        return cutVolume if cutVolume is not None else p.anatomyVolume

    def startFeedback(self, parameterNode, sound: bool = True, volume: float = 1.0) -> desktopfeedback.DesktopFeedback:
        """The nerve monitor's meter and the drill sound for the parameter node's cut session (silent, with a
        message, without an audio device)."""
        feedback = desktopfeedback.DesktopFeedback(slicer.modules.volumecutting.logic())
        feedback.set_volume(volume)
        feedback.start(parameterNode.cutNode, sound=sound)
        return feedback


#
# VolumeCuttingToolsTest
#


class VolumeCuttingToolsTest(ScriptedLoadableModuleTest):
    """Slicer self-test: the desktop path over the same library the pytest suite covers."""

    def setUp(self):
        slicer.mrmlScene.Clear()

    def runTest(self):
        self.setUp()
        self.test_PhantomAndBoneSegmentation()
        self.setUp()
        self.test_ToolConfiguration()
        for name in selftests.CASES:
            self.setUp()
            self.runSelfTestCase(name)

    def test_PhantomAndBoneSegmentation(self):
        self.delayDisplay("Generating a phantom")
        logic = VolumeCuttingToolsLogic()
        volume, segmentation = logic.generatePhantom(48, 1.0, 1)
        self.assertEqual(volume.GetImageData().GetDimensions(), (48, 48, 48))
        self.assertGreater(segmentation.GetSegmentation().GetNumberOfSegments(), 5)
        cuttingLogic = slicer.util.getModuleLogic("VolumeCutting")
        bone = cuttingLogic.CreateBoneSegmentation(volume, 700.0, 200.0, 0.0)
        self.assertIsNotNone(bone)
        cutNode = cuttingLogic.AddVolumeCutNode(volume, segmentation)
        self.assertTrue(cutNode.SetSegmentProtected("FacialNerve", True))
        self.assertTrue(cuttingLogic.CheckInputs(cutNode, slicer.vtkMRMLMessageCollection()))
        self.delayDisplay("Test passed")

    def test_ToolConfiguration(self):
        self.delayDisplay("Configuring a tool from a preset")
        logic = VolumeCuttingToolsLogic()
        parameterNode = logic.getParameterNode()
        parameterNode.toolPreset = "Diamond burr 2 mm"
        logic.loadPreset(parameterNode)
        tool = logic.createTool(parameterNode)
        self.assertEqual(toolconfig.from_tool_node(tool), TOOL_PRESETS["Diamond burr 2 mm"].parameters)
        parameterNode.toolNode = tool
        parameterNode.toolDiameter = 3.0
        logic.applyToTool(parameterNode)
        self.assertEqual(tool.GetDiameter(), 3.0)
        self.assertEqual(logic.listDevices()[0].device_id, "mouse")
        self.delayDisplay("Test passed")

    def runSelfTestCase(self, name):
        """A case of VolumeCuttingLib.jobs.selftests, the same code pytest runs against slicer-core."""
        with tempfile.TemporaryDirectory(prefix=f"volumecutting-{name}-") as folder:
            context = selftests.SelfTestContext(slicer.mrmlScene, slicer.util.getModuleLogic("VolumeCutting"), Path(folder), self.delayDisplay)
            selftests.CASES[name](context)
        self.delayDisplay(f"{name}: passed")
