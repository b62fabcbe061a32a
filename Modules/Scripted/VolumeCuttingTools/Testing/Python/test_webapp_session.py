"""The web application's session without a browser (VolumeCuttingLib.webapp.session, views, app helpers).

A real scene with trame-slicer's SlicerApp and the VolumeCutting logic, the
temporal-bone phantom, strokes through the logic, exports read back with
Slicer's storage nodes. The page itself is tested in test_webapp_browser.py.
"""

import argparse
import time
import zipfile

import numpy as np
import pyigtl
import pytest
import slicer
import vtk
from vtkmodules.util import numpy_support

from VolumeCuttingLib.collaboration import igtlbridge
from VolumeCuttingLib.collaboration.igtlclient import RecordingClient
from VolumeCuttingLib.data import owndata
from VolumeCuttingLib.scene.application import HeadlessSlicer
from VolumeCuttingLib.webapp import app as webapp
from VolumeCuttingLib.webapp import views
from VolumeCuttingLib.webapp.session import DrillSession, SessionError, SoftCutSession, tool_pose


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    from trame_slicer.core import SlicerApp

    slicer_app = SlicerApp()
    logic = slicer_app.register_module_logic(slicer.vtkSlicerVolumeCuttingLogic(), logic_name="VolumeCutting")
    drill_session = DrillSession(slicer_app.scene, logic, tmp_path_factory.mktemp("webapp-session"))
    steps = list(drill_session.loading("phantom"))
    assert [text for _, text in steps][0] == "Reading the CT" and steps[-1] == (1.0, "Ready")
    assert [f for f, _ in steps] == sorted(f for f, _ in steps)
    yield drill_session
    drill_session.close()


def lateral_point(session, y=0.0, z=0.0):
    """The first voxel of the mastoid cortex seen from the patient's right at (y, z) (RAS mm)."""
    from VolumeCuttingLib.cutting import drilling

    return drilling.lateral_entry(session.volume, y, z, threshold=1000.0)


def stroke(session, points, depth, restore=False):
    assert session.begin_stroke(restore=restore)
    for point in points:
        assert session.move_tool(tool_pose(point, (-1.0, 0.0, 0.0), depth, session.tool_reach()))
    assert session.end_stroke()


def test_tool_pose_puts_the_tip_at_the_depth_with_the_shaft_towards_the_eye():
    pose = tool_pose((10.0, 2.0, -3.0), (0.0, 0.0, -2.0), 1.5, 2.0)
    matrix = np.array([[pose.GetElement(r, c) for c in range(4)] for r in range(4)])
    np.testing.assert_allclose(matrix[:3, :3] @ matrix[:3, :3].T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(matrix[:3, :3]), 1.0)
    np.testing.assert_allclose(matrix[:3, 2], (0.0, 0.0, 1.0))  # shaft back along the view
    center = matrix[:3, 3]
    np.testing.assert_allclose(center, (10.0, 2.0, -3.0 - 1.5 + 2.0))  # tip 1.5 mm below the surface
    with pytest.raises(ValueError, match="no length"):
        tool_pose((0, 0, 0), (0, 0, 0), 1.0, 1.0)


def test_roles_and_a_stroke_that_touches_a_protected_segment(session):
    session.set_role("MastoidBone", "protected")
    rows = {row.segment_id: row for row in session.segment_rows()}
    assert rows["MastoidBone"].role == "protected" and rows["MastoidCortex"].role == "cuttable"
    assert rows["MastoidCortex"].color.startswith("#") and len(rows["MastoidCortex"].color) == 7
    with pytest.raises(SessionError, match=r"not one of 'cuttable', 'protected' or '' \(none\)"):
        session.set_role("MastoidBone", "sometimes")
    with pytest.raises(SessionError, match="no segment 'Brain'"):
        session.set_role("Brain", "protected")

    entry = lateral_point(session)
    # 1 mm into the cortex: cortex removed, nothing protected touched.
    stroke(session, [entry + (0.0, 0.5 * i, 0.0) for i in range(8)], 1.0)
    removed = session.removed_volumes()
    assert removed["MastoidCortex"] > 1.0 and removed["MastoidBone"] == 0.0
    assert session.contact() is None
    # 4 mm in: through the cortex into the protected bone, which stays.
    stroke(session, [entry + (0.0, -4.0, 0.5 * i) for i in range(6)], 4.0)
    contact = session.contact()
    assert contact is not None and contact.segment_id == "MastoidBone" and contact.depth_mm > 0.5
    assert session.removed_volumes()["MastoidBone"] == 0.0
    assert session.undo_redo_counts() == (2, 0)

    total = session.total_removed_volume()
    assert session.undo()
    assert session.total_removed_volume() < total
    assert session.redo()
    assert session.total_removed_volume() == pytest.approx(total, abs=1e-6)
    session.set_role("MastoidBone", "cuttable")


def test_restore_adds_bone_back_inside_the_cut(session):
    entry = lateral_point(session, y=6.0, z=-6.0)
    stroke(session, [entry], 2.0)
    removed = session.total_removed_volume()
    stroke(session, [entry], 2.0, restore=True)
    assert session.total_removed_volume() < removed - 1.0


def test_openigtlink_is_off_by_default_and_its_drill_poses_cut_a_stroke_of_the_session(session):
    """``--openigtlink PORT``: a client's DrillTool poses go through the web session's strokes, as the mouse's do."""
    parser = argparse.ArgumentParser()
    webapp.add_arguments(parser)
    assert webapp.options_from_arguments(parser.parse_args([])).openigtlink is None
    options = webapp.options_from_arguments(parser.parse_args(["--openigtlink", "0"])).openigtlink
    assert options.port == 0 and options.host == "127.0.0.1"
    with pytest.raises(SystemExit, match="goes with --openigtlink"):
        webapp.options_from_arguments(parser.parse_args(["--openigtlink-host", "0.0.0.0"]))

    entry = lateral_point(session, y=-6.0, z=6.0)
    undo_steps = session.undo_redo_counts()[0]
    removed = session.total_removed_volume()
    with igtlbridge.IgtlBridge(options) as bridge:
        bridge.attach(session.logic, session.cut_node)
        client = RecordingClient("127.0.0.1", bridge.port)
        try:
            assert client.wait_for(lambda c: c.messages("IMAGE"))
            for i in range(8):
                pose = tool_pose(entry + (0.0, 0.5 * i, 0.0), (-1.0, 0.0, 0.0), 2.0, session.tool_reach())
                matrix = np.array([[pose.GetElement(r, c) for c in range(4)] for r in range(4)])
                client.send(pyigtl.TransformMessage(matrix, device_name=igtlbridge.DRILL_DEVICE))
            applied, deadline = {}, time.monotonic() + 5.0
            while not applied.get("strokes_ended") and time.monotonic() < deadline:
                for key, count in bridge.process_incoming(session).items():
                    applied[key] = applied.get(key, 0) + count
                time.sleep(0.005)
            assert applied == {"drill": 8, "strokes_ended": 1}
            assert not session.in_stroke and session.undo_redo_counts()[0] == undo_steps + 1
            assert session.total_removed_volume() > removed + 1.0
            assert client.wait_for(lambda c: len(c.messages("IMAGE")) > 1)  # the mirror follows the cut
        finally:
            client.close()
    assert session.undo()


def test_tool_parameters_and_presets(session):
    name = session.preset_names()[0]
    params = session.apply_preset(name)
    assert session.tool_parameters() == params
    assert session.set_tool(diameter=3.0).diameter == 3.0
    assert session.tool_reach() == pytest.approx(1.5)
    from VolumeCuttingLib.config import toolconfig

    with pytest.raises(toolconfig.ToolConfigError, match="diameter"):
        session.set_tool(diameter=70.0)
    assert session.tool_parameters().diameter == 3.0  # the node kept its value
    with pytest.raises(SessionError, match="no tool preset named 'Chainsaw'"):
        session.apply_preset("Chainsaw")
    session.set_tool(diameter=4.0)


def test_exports_read_back_with_slicer(session, tmp_path):
    def node_classes():
        scene = session.scene
        return {scene.GetNthNode(i).GetID(): scene.GetNthNode(i).GetClassName() for i in range(scene.GetNumberOfNodes())}

    before = node_classes()
    paths = {kind: session.export(kind) for kind in ("stl", "segmentation", "drilled_ct")}
    assert node_classes() == before  # exports leave nothing behind
    paths["scene"] = session.export("scene")
    # Saving a scene gives its data nodes storage nodes, as desktop Slicer does; nothing else.
    added = {node_id: name for node_id, name in node_classes().items() if node_id not in before}
    assert added and all(name.endswith("StorageNode") for name in added.values())
    check_exports(paths, session.total_removed_volume(), tmp_path)


def open_edges(mesh) -> int:
    """How many edges of a mesh are on a boundary or shared by more than two faces (0: closed, printable)."""
    edges = vtk.vtkFeatureEdges()
    edges.SetInputData(mesh)
    edges.BoundaryEdgesOn()
    edges.NonManifoldEdgesOn()
    edges.FeatureEdgesOff()
    edges.ManifoldEdgesOff()
    edges.Update()
    return edges.GetOutput().GetNumberOfCells()


def check_exports(paths, removed_mm3, tmp_path, tolerance_mm3=1e-6):
    """Read every export back with Slicer Core: a closed STL, a segment, a CT, a bundle with the same cut."""
    scene = HeadlessSlicer(tmp_path / "readback-cache")
    model = scene.scene.AddNewNodeByClass("vtkMRMLModelNode")
    storage = slicer.vtkMRMLModelStorageNode()
    storage.SetFileName(str(paths["stl"]))
    assert storage.ReadData(model)
    assert model.GetPolyData().GetNumberOfCells() > 100
    assert open_edges(model.GetPolyData()) == 0  # closed

    segmentation = scene.scene.AddNewNodeByClass("vtkMRMLSegmentationNode")
    segmentation_storage = slicer.vtkMRMLSegmentationStorageNode()
    segmentation_storage.SetFileName(str(paths["segmentation"]))
    assert segmentation_storage.ReadData(segmentation)
    assert segmentation.GetSegmentation().GetNumberOfSegments() == 1

    volume = scene.scene.AddNewNodeByClass("vtkMRMLScalarVolumeNode")
    volume_storage = slicer.vtkMRMLVolumeArchetypeStorageNode()
    volume_storage.SetFileName(str(paths["drilled_ct"]))
    assert volume_storage.ReadData(volume)
    assert volume.GetImageData().GetScalarRange()[0] <= -999.0  # drilled voxels are air

    bundle = HeadlessSlicer(tmp_path / "bundle-cache")
    bundle.load_bundle(paths["scene"])
    cut_nodes = [bundle.scene.GetNthNodeByClass(i, "vtkMRMLVolumeCutNode")
                 for i in range(bundle.scene.GetNumberOfNodesByClass("vtkMRMLVolumeCutNode"))]
    assert len(cut_nodes) == 1
    assert bundle.volume_cutting_logic.GetRemovedVolume(cut_nodes[0]) == pytest.approx(removed_mm3, abs=tolerance_mm3)


def test_a_load_that_fails_keeps_the_previous_data(session, tmp_path):
    cut_node, nodes_before = session.cut_node, session.scene.GetNumberOfNodes()
    removed = session.total_removed_volume()
    not_an_image = tmp_path / "scan.nrrd"
    not_an_image.write_text("these are notes, not a CT\n")
    with pytest.raises(owndata.InputError, match="scan.nrrd"):
        session.load("own", ct_path=not_an_image)
    assert session.cut_node is cut_node and session.scene.GetNumberOfNodes() == nodes_before
    assert session.total_removed_volume() == removed
    with pytest.raises(SessionError, match="Give the CT"):
        session.load("own")


def test_only_allowed_folders_are_read(tmp_path):
    allowed = tmp_path / "scans"
    allowed.mkdir()
    (allowed / "ct.nrrd").write_bytes(b"")
    assert webapp.path_allowed(allowed / "ct.nrrd", [allowed.resolve()])
    assert webapp.path_allowed(allowed / "series" / "missing.dcm", [allowed.resolve()])
    assert not webapp.path_allowed(allowed / ".." / "other.nrrd", [allowed.resolve()])
    assert not webapp.path_allowed("/etc/passwd", [allowed.resolve()])
    (allowed / "passwd").symlink_to("/etc/passwd")
    assert not webapp.path_allowed(allowed / "passwd", [allowed.resolve()])


def test_a_zip_that_reaches_outside_its_folder_is_refused(tmp_path):
    archive = tmp_path / "series.zip"
    with zipfile.ZipFile(archive, "w") as bundle:
        bundle.writestr("../../outside.txt", "x")
    with pytest.raises(SessionError, match="outside its folder"):
        webapp.unpack_upload([archive], tmp_path, 2**20)
    assert not (tmp_path.parent / "outside.txt").exists()
    huge = tmp_path / "huge.zip"
    with zipfile.ZipFile(huge, "w", compression=zipfile.ZIP_DEFLATED) as bundle:
        bundle.writestr("ct.nrrd", b"\0" * (3 * 2**20))
    with pytest.raises(SessionError, match="unpacked it holds 3.0 MB"):
        webapp.unpack_upload([huge], tmp_path / "huge", 2**20)


def place_camera_above(renderer, height):
    """The camera on the z axis at that height, looking down at the origin."""
    camera = renderer.GetActiveCamera()
    camera.SetPosition(0, 0, height)
    camera.SetFocalPoint(0, 0, 0)
    renderer.ResetCameraClippingRange()
    return camera


def plane_in_offscreen_view(size, half_width, height, resolution=1):
    """A square plane at z = height seen by an offscreen renderer of that size: (renderer, window, plane)."""
    renderer = vtk.vtkRenderer()
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(True)
    window.SetMultiSamples(0)
    window.SetSize(*size)
    window.AddRenderer(renderer)
    plane = vtk.vtkPlaneSource()
    plane.SetOrigin(-half_width, -half_width, height)
    plane.SetPoint1(half_width, -half_width, height)
    plane.SetPoint2(-half_width, half_width, height)
    plane.SetResolution(resolution, resolution)
    plane.Update()
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputData(plane.GetOutput())
    actor = vtk.vtkActor()
    actor.SetMapper(mapper)
    renderer.AddActor(actor)
    return renderer, window, plane.GetOutput()


def test_surface_depth_finds_the_surface_under_a_pixel():
    renderer, window, _ = plane_in_offscreen_view((200, 160), 50, 5.0)
    place_camera_above(renderer, 100)
    depth = views.SurfaceDepth(renderer)
    window.Render()
    point, direction = depth.surface_point(0.5, 0.5)
    np.testing.assert_allclose(point, (0.0, 0.0, 5.0), atol=0.05)
    np.testing.assert_allclose(direction, (0.0, 0.0, -1.0), atol=1e-6)
    point, _ = depth.surface_point(0.75, 0.5)
    assert point[0] > 5.0 and point[2] == pytest.approx(5.0, abs=0.05)
    frozen = depth.snapshot()
    place_camera_above(renderer, 60)
    window.Render()
    np.testing.assert_allclose(frozen.surface_point(0.5, 0.5)[0], (0.0, 0.0, 5.0), atol=0.05)
    assert depth.surface_point(1.5, 0.5) is None
    window.Finalize()


def test_a_burr_follows_the_surface_under_its_footprint_not_each_pixel():
    """A tilted plane with 0.1 mm ripples of 1.7 mm (the rendered phantom's surface), seen at 0.07 mm per pixel.

    Per pixel the surface point rides the ripples, and on a frame drawn while the camera moved (one depth per
    4 x 4 pixels) it jumps at each block: a stroke at a fixed depth copied both into its floor as bands. Over a
    1 mm footprint the point lies on the plane within a fraction of the ripple.
    """
    renderer, window, surface = plane_in_offscreen_view((240, 200), 20, 0.0, resolution=800)
    xyz = numpy_support.vtk_to_numpy(surface.GetPoints().GetData()).astype(float)
    tilt = 0.3  # mm of height per mm along x
    amplitude, period = 0.1, 1.7
    xyz[:, 2] = tilt * xyz[:, 0] + amplitude * np.sin(2.0 * np.pi * xyz[:, 0] / period)
    surface.GetPoints().SetData(numpy_support.numpy_to_vtk(xyz, deep=True))
    place_camera_above(renderer, 30)
    depth = views.SurfaceDepth(renderer)
    window.Render()
    coarse = depth.snapshot()
    rows, columns = coarse.depth.shape
    blocks = coarse.depth[: rows - rows % 4, : columns - columns % 4]
    coarse.depth[: rows - rows % 4, : columns - columns % 4] = np.repeat(np.repeat(blocks[::4, ::4], 4, axis=0), 4, axis=1)

    def heights(source, footprint):
        # Height above the ripple-free plane z = tilt x along a stroke (the rays are vertical within 0.1 degrees).
        points = [source.surface_point(fx, 0.5, footprint_mm=footprint)[0] for fx in np.linspace(0.3, 0.7, 81)]
        return np.array([point[2] - tilt * point[0] for point in points])

    # What a floor shows is how the height swings along the stroke (a constant offset leaves it flat).
    swing = {(name, footprint): float(np.ptp(heights(source, footprint)))
             for name, source in (("fine", depth), ("coarse", coarse)) for footprint in (0.0, 1.0)}
    assert swing["fine", 0.0] > 0.15 and swing["coarse", 0.0] > 0.15, swing
    assert swing["fine", 1.0] < 0.03 and swing["coarse", 1.0] < 0.03, swing
    assert np.abs(heights(depth, 1.0)).max() < 0.03
    window.Finalize()


@pytest.mark.parametrize("shape, sizes", [("Sphere", {"diameter": 5.0}), ("Cylinder", {"diameter": 3.0, "length": 8.0}),
                                           ("DiskSaw", {"diameter": 20.0, "thickness": 1.0}),
                                           ("Blade", {"width": 10.0, "length": 30.0, "thickness": 0.6})])
def test_the_glyph_has_the_tool_shape_and_size(session, shape, sizes):
    from VolumeCuttingLib.webapp.session import half_length_along_shaft

    params = session.set_tool(shape=shape, **sizes)
    display = session.tool_node.GetVolumeCutToolDisplayNode()
    display.SetShowAxis(False)
    bounds = views.tool_glyph(session.tool_node).GetBounds()
    across = params.width if shape == "Blade" else params.diameter
    assert bounds[1] - bounds[0] == pytest.approx(across, rel=0.02)
    assert bounds[4] == pytest.approx(-half_length_along_shaft(session.tool_node), rel=0.02)
    assert bounds[5] == pytest.approx(half_length_along_shaft(session.tool_node), rel=0.02)
    display.SetShowAxis(True)
    assert views.tool_glyph(session.tool_node).GetBounds()[5] == pytest.approx(bounds[5] + 25.0, rel=0.02)
    session.set_tool(shape="Sphere", diameter=4.0)


# --------------------------------------------------------------------------- SoftCut


@pytest.fixture(scope="module")
def head_session(tmp_path_factory):
    """The example head CT as the page loads it (bone segmented automatically), for SoftCut's cheek outline."""
    from trame_slicer.core import SlicerApp

    slicer_app = SlicerApp()
    logic = slicer_app.register_module_logic(slicer.vtkSlicerVolumeCuttingLogic(), logic_name="VolumeCutting")
    drill_session = DrillSession(slicer_app.scene, logic, tmp_path_factory.mktemp("webapp-softcut"))
    drill_session.load("headct")
    yield drill_session
    drill_session.close()


def closed_stl(path):
    reader = vtk.vtkSTLReader()
    reader.SetFileName(str(path))
    reader.Update()
    mesh = reader.GetOutput()
    return mesh, open_edges(mesh)


def test_softcut_plans_previews_carves_measures_and_exports_the_cheek(head_session):
    softcut = SoftCutSession(head_session)
    cut = head_session.cut_node
    softcut.show_skin(True)
    assert cut.GetSurfaceIsoValue() == -500.0 and not cut.GetThinBoneShading()
    # The skin shows through a cuttable soft-tissue segment, drawn under the bone.
    skin = SoftCutSession.SOFT_TISSUE_SEGMENT_ID
    assert cut.IsSegmentCuttable(skin) and head_session.segmentation.GetDisplayNode().GetSegmentVisibility3D(skin)
    assert head_session.segmentation.GetSegmentation().GetSegmentIndex(skin) == 0
    assert softcut.has_example_outline()
    assert softcut.use_example_outline() == 20 and softcut.normal_mode == "average"
    assert len(softcut.outline_points()) == 20
    assert softcut.outline_polydata().GetNumberOfPoints() > 20 * 10  # balls and a closed tube

    # Previews change nothing in the cut: the preview field holds them.
    softcut.preview(4.0)
    assert softcut.previewing and cut.GetPreviewCutField() is not None
    softcut.preview(8.0)
    assert head_session.total_removed_volume() == 0.0 and head_session.undo_redo_counts() == (0, 0)

    rows = softcut.carve()
    assert not softcut.previewing and softcut.depth_mm == 8.0
    removed = head_session.total_removed_volume()
    assert head_session.undo_redo_counts() == (1, 0)
    volume, unit = rows["Resected volume"]
    # The main job's figure for this outline: 5644 mm3, 35.5 x 25.1 x 16.4 mm.
    assert unit == "mm3" and 4000.0 < volume < 8000.0
    assert 28.0 < rows["Length"][0] < 45.0 and 18.0 < rows["Width"][0] < 35.0 and 8.0 <= rows["Thickness"][0] < 25.0
    assert rows["Surface area"][0] > 0.0 and rows["Surface area"][1] == "mm2"
    # The cut also opens the air just above the skin: the removed volume is at least the resected tissue.
    assert removed > 0.9 * volume
    assert head_session.removed_volumes()[skin] > 0.9 * volume  # in the segments table

    assert head_session.undo() and head_session.total_removed_volume() == 0.0
    assert head_session.redo() and head_session.total_removed_volume() == pytest.approx(removed, rel=1e-9)

    mesh, open_edges = closed_stl(softcut.export_stl())
    assert mesh.GetNumberOfPolys() > 500 and open_edges == 0
    bounds = mesh.GetBounds()
    diagonal = np.linalg.norm([bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]])
    assert rows["Length"][0] < diagonal < 2.0 * rows["Length"][0] + 2.0 * rows["Thickness"][0]

    # Back to drilling: the bone surface again.
    softcut.show_skin(False)
    assert cut.GetSurfaceIsoValue() == 300.0 and cut.GetThinBoneShading()
    assert not head_session.segmentation.GetDisplayNode().GetSegmentVisibility3D(skin) and cut.IsSegmentCuttable(skin)
    assert head_session.undo() and head_session.total_removed_volume() == 0.0


def test_softcut_bad_input_carves_nothing(head_session):
    softcut = SoftCutSession(head_session)
    undo_steps = head_session.undo_redo_counts()
    removed = head_session.total_removed_volume()
    with pytest.raises(SessionError, match="no SoftCut outline yet"):
        softcut.carve(5.0)
    points = __import__("VolumeCuttingLib.cutting.softcut", fromlist=["picked_points"]).picked_points(
        head_session.volume, (42.0, 62.0, -40.0), (-0.7, -0.7, -0.1), (10.0, 8.0), count=4)
    softcut.add_point(points[0])
    softcut.add_point(points[1])
    with pytest.raises(SessionError, match="3") as error:
        softcut.preview(5.0)
    assert "2" in str(error.value)  # the logic's message: how many there are, how many are needed
    assert not softcut.previewing
    # A point 25 mm out in the air in front of the cheek.
    softcut.add_point(points[2] + 25.0 * np.array([0.7, 0.7, 0.1]))
    with pytest.raises(SessionError, match="control point 3 .* from the skin"):
        softcut.carve(5.0)
    assert softcut.remove_last_point() == 2
    softcut.add_point(points[2])
    softcut.add_point(points[3])
    with pytest.raises(SessionError, match="between 0.5 and 20"):
        softcut.carve(0.0)
    with pytest.raises(SessionError, match="not one of local, average"):
        softcut.set_normal_mode("sideways")
    assert head_session.undo_redo_counts() == undo_steps and head_session.total_removed_volume() == removed
    # The good outline carves after all that.
    softcut.carve(3.0)
    assert head_session.total_removed_volume() > removed
    assert head_session.undo()
    softcut.clear_outline()
    assert softcut.outline_points() == []


def test_softcut_example_outline_needs_the_head_ct(session):
    softcut = SoftCutSession(session)
    assert not softcut.has_example_outline()
    with pytest.raises(SessionError, match="example head CT"):
        softcut.use_example_outline()


def test_an_own_segmentation_opens_with_roles_given_by_name(tmp_path):
    """``vc app --ct --segmentation --cuttable --protected``: roles by name, as the main job takes them."""
    parser = argparse.ArgumentParser()
    webapp.add_arguments(parser)
    options = webapp.options_from_arguments(parser.parse_args(
        ["--ct", "ct.nrrd", "--segmentation", "labels.nrrd", "--cuttable", "Mastoid bone,Air cells", "--protected", "Facial nerve"]))
    assert (options.cuttable, options.protected) == ("Mastoid bone,Air cells", "Facial nerve")
    with pytest.raises(SystemExit, match="name segments of --segmentation"):
        webapp.options_from_arguments(parser.parse_args(["--ct", "ct.nrrd", "--protected", "Facial nerve"]))
    from test_assessment_owndata import own_case
    from trame_slicer.core import SlicerApp

    slicer_app = SlicerApp()
    logic = slicer_app.register_module_logic(slicer.vtkSlicerVolumeCuttingLogic(), logic_name="VolumeCutting")
    ct_path, labels_path = own_case(tmp_path)
    own = DrillSession(slicer_app.scene, logic, tmp_path / "own")
    own.load("own", ct_path=ct_path, segmentation_path=labels_path)
    assert {row.role for row in own.segment_rows()} == {""}  # without names every segment starts without a role
    cut_node = own.cut_node
    with pytest.raises(owndata.InputError, match="no segment named 'Cochlea'.*Facial nerve"):
        own.load("own", ct_path=ct_path, segmentation_path=labels_path, cuttable_names="temporal bone",
                 protected_names="Cochlea")
    assert own.cut_node is cut_node  # the data before the refused load stays
    own.load("own", ct_path=ct_path, segmentation_path=labels_path, cuttable_names="temporal bone",
             protected_names="facial_nerve")
    roles = {row.name: row.role for row in own.segment_rows()}
    assert roles["Temporal bone"] == "cuttable" and roles["Facial nerve"] == "protected", roles
    with pytest.raises(SessionError, match="Roles by name need the segmentation"):
        own.load("own", ct_path=ct_path, cuttable_names="temporal bone")
    own.close()
