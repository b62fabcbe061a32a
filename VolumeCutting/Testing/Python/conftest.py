"""Shared fixtures of the VolumeCutting module's Python tests."""

import pytest
import slicer


@pytest.fixture()
def scene_xml_round_trip():
    """A function that writes a volume-cut node's scene to XML and returns the node read back from it."""
    # The scenes read back live as long as the test: their nodes point to them.
    scenes = []

    def round_trip(node):
        scene = node.GetScene()
        scene.SetSaveToXMLString(1)
        scene.Commit()
        reloaded = slicer.vtkMRMLScene()
        reloaded.RegisterNodeClass(slicer.vtkMRMLVolumeCutNode())
        reloaded.SetLoadFromXMLString(1)
        reloaded.SetSceneXMLString(scene.GetSceneXMLString())
        reloaded.Import()
        scenes.append(reloaded)
        return reloaded.GetFirstNodeByClass("vtkMRMLVolumeCutNode")

    return round_trip
