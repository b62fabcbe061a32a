"""VolumeCuttingTools: the Python side of VolumeCutting in desktop Slicer.

Thin by design: the widget only connects the GUI to VolumeCuttingToolsLogic, and
the logic forwards to VolumeCuttingLib (Qt-free, tested with pytest against
slicer-core) and to the C++ vtkSlicerVolumeCuttingLogic. Tool configuration
(burrs, saws, sensibility) is added here as those tools are built.
"""

import logging
from typing import Annotated

import slicer
import vtk
from slicer.parameterNodeWrapper import WithinRange, parameterNodeWrapper
from slicer.ScriptedLoadableModule import (
    ScriptedLoadableModule,
    ScriptedLoadableModuleLogic,
    ScriptedLoadableModuleTest,
    ScriptedLoadableModuleWidget,
)
from slicer.util import VTKObservationMixin

from VolumeCuttingLib import headct, phantom


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
    """

    phantomSize: Annotated[int, WithinRange(32, 256)] = 128
    phantomSpacing: Annotated[float, WithinRange(0.1, 2.0)] = 0.4
    phantomSeed: Annotated[int, WithinRange(0, 2**31 - 1)] = 0
    anatomyVolume: slicer.vtkMRMLScalarVolumeNode
    segmentation: slicer.vtkMRMLSegmentationNode


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
        self.initializeParameterNode()

    def cleanup(self) -> None:
        self.removeObservers()

    def enter(self) -> None:
        self.initializeParameterNode()

    def exit(self) -> None:
        if self._parameterNode:
            self._parameterNode.disconnectGui(self._parameterNodeGuiTag)
            self._parameterNodeGuiTag = None

    def onSceneStartClose(self, caller, event) -> None:
        self.setParameterNode(None)

    def onSceneEndClose(self, caller, event) -> None:
        if self.parent.isEntered:
            self.initializeParameterNode()

    def initializeParameterNode(self) -> None:
        self.setParameterNode(self.logic.getParameterNode())

    def setParameterNode(self, inputParameterNode) -> None:
        if self._parameterNode:
            self._parameterNode.disconnectGui(self._parameterNodeGuiTag)
        self._parameterNode = inputParameterNode
        if self._parameterNode:
            self._parameterNodeGuiTag = self._parameterNode.connectGui(self.ui)

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
