"""Tool configuration without Qt (VolumeCuttingLib.config.toolconfig and inputdevices).

Real scenes, real tool and cut nodes; devices faced through umockdev where it
is installed (Debian ``umockdev``), as /work/shared/notes/devices.md describes.
"""

import copy
import json
import shutil
import struct
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import slicer

from VolumeCuttingLib.config import inputdevices, toolconfig
from VolumeCuttingLib.config.toolconfig import PresetError, ToolConfigError, ToolParameters
from VolumeCuttingLib.scene.application import HeadlessSlicer

PRESETS = toolconfig.load_presets()
LIBRARY_DIR = Path(toolconfig.__file__).resolve().parent


@pytest.fixture
def application():
    return HeadlessSlicer()


@pytest.fixture
def shipped_document():
    return json.loads(toolconfig.default_presets_path().read_text())


# ---------------------------------------------------------------- presets


@pytest.mark.parametrize("preset", PRESETS, ids=[p.name for p in PRESETS])
def test_every_shipped_preset_applies_and_reads_back(application, preset):
    tool = toolconfig.create_tool_node(application.scene, toolconfig.from_preset(preset), preset.name)
    assert toolconfig.from_tool_node(tool) == preset.parameters
    assert tool.GetName() == preset.name
    assert isinstance(tool.GetDisplayNode(), slicer.vtkMRMLVolumeCutToolDisplayNode)
    assert isinstance(tool.GetParentTransformNode(), slicer.vtkMRMLLinearTransformNode)
    assert preset.category in ("Otology", "Spine")
    # Every preset says where its speed comes from.
    assert "Speed" in preset.description
    assert "et al." in preset.description or "study" in preset.description


def test_the_presets_cover_otology_and_spine():
    by_name = {p.name: p.parameters for p in PRESETS}
    cutting = sorted(p.diameter for p in by_name.values() if p.shape == "Sphere" and p.burr_type == "Cutting")
    diamond = sorted(p.diameter for p in by_name.values() if p.shape == "Sphere" and p.burr_type == "Diamond")
    assert set(range(1, 8)) <= set(cutting)
    assert set(range(1, 6)) <= set(diamond)
    matchstick = [p for p in by_name.values() if p.shape == "Cylinder"]
    assert [p.diameter for p in matchstick] == [3.0]
    assert any(p.shape == "DiskSaw" for p in by_name.values())
    assert any(p.shape == "Blade" for p in by_name.values())


def test_presets_are_found_from_the_installed_wheel(tmp_path):
    """In a fresh interpreter that sees only site-packages, the wheel's copy of the file is used."""
    probe = "from VolumeCuttingLib.config import toolconfig as t; print(t.__file__); print(t.default_presets_path()); print(len(t.load_presets()))"
    result = subprocess.run([sys.executable, "-I", "-c", probe], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    module_file, presets_file, count = result.stdout.split()
    assert "site-packages" in module_file
    # Resources/Presets/<file> inside the package root (toolconfig.py sits in its config/ subpackage).
    assert Path(presets_file).parent.parent.parent == Path(module_file).parents[1]
    assert int(count) == len(PRESETS)


def write_presets(tmp_path, document, name="presets.json"):
    path = tmp_path / name
    path.write_text(document if isinstance(document, str) else json.dumps(document))
    return path


def broken(document, index, **changes):
    """A copy of the presets with preset ``index`` changed (a value of None removes the field)."""
    document = copy.deepcopy(document)
    for key, value in changes.items():
        if value is None:
            del document["presets"][index][key]
        else:
            document["presets"][index][key] = value
    return document


@pytest.mark.parametrize(
    "changes, field, words",
    [
        ({"speed": None}, "speed", "missing"),
        ({"diameter": None}, "diameter", "missing"),
        ({"diameter": 9.5}, "diameter", "outside 1 to 7 mm for a Sphere"),
        ({"diameter": "big"}, "diameter", "not a number"),
        ({"power": True}, "power", "not a number"),
        ({"power": 1.2}, "power", "outside 0 to 1"),
        ({"shape": "Hammer"}, "shape", "not a tool shape"),
        ({"shape": "Mesh"}, "shape", "needs a model node"),
        ({"burrType": "Ceramic"}, "burrType", "not a burr type"),
        ({"width": 5.0}, "width", "not used by a Sphere tool"),
        ({"colour": "red"}, "colour", "not a preset field"),
        ({"name": ""}, "name", "non-empty text"),
        ({"name": "Cutting burr 1 mm"}, "name", "used by an earlier preset"),
    ],
)
def test_broken_presets_name_file_preset_and_field(tmp_path, shipped_document, changes, field, words):
    path = write_presets(tmp_path, broken(shipped_document, 3, **changes))
    with pytest.raises(PresetError) as raised:
        toolconfig.load_presets(path)
    message = str(raised.value)
    assert str(path) in message
    assert "preset #4" in message
    assert f"field '{field}'" in message
    assert words in message
    assert raised.value.field == field


def test_broken_preset_files(tmp_path, shipped_document):
    bad_json = write_presets(tmp_path, '{"format": "VolumeCuttingToolPresets", "presets": [', "bad.json")
    with pytest.raises(PresetError, match=r"bad\.json: not valid JSON at line 1"):
        toolconfig.load_presets(bad_json)
    with pytest.raises(PresetError, match="cannot read"):
        toolconfig.load_presets(tmp_path / "missing.json")
    with pytest.raises(PresetError, match="not a tool presets file"):
        toolconfig.load_presets(write_presets(tmp_path, {"presets": []}, "other.json"))
    with pytest.raises(PresetError, match="version 7 is not supported"):
        toolconfig.load_presets(write_presets(tmp_path, dict(shipped_document, version=7), "v7.json"))
    with pytest.raises(PresetError, match="non-empty list"):
        toolconfig.load_presets(write_presets(tmp_path, dict(shipped_document, presets=[]), "empty.json"))
    with pytest.raises(PresetError, match="preset #2: a preset must be a JSON object"):
        toolconfig.load_presets(write_presets(tmp_path, dict(shipped_document, presets=[shipped_document["presets"][0], 5]), "five.json"))
    # A cylinder needs its length, a blade its three sizes.
    cylinder = next(i for i, p in enumerate(shipped_document["presets"]) if p["shape"] == "Cylinder")
    with pytest.raises(PresetError, match="field 'length': missing"):
        toolconfig.load_presets(write_presets(tmp_path, broken(shipped_document, cylinder, length=None), "cyl.json"))


# ---------------------------------------------------------------- parameters and nodes


@pytest.mark.parametrize(
    "changes, field",
    [
        ({"shape": "Hammer"}, "shape"),
        ({"burr_type": "cutting"}, "burr_type"),
        ({"diameter": 0.5}, "diameter"),
        ({"diameter": float("nan")}, "diameter"),
        ({"shape": "DiskSaw", "diameter": 3.0}, "diameter"),
        ({"length": 0.0}, "length"),
        ({"thickness": 6.0}, "thickness"),
        ({"width": 60.0}, "width"),
        ({"power": -0.5}, "power"),
        ({"speed": 1e6}, "speed"),
        ({"speed": "fast"}, "speed"),
        ({"use_cut_node_roles": 1}, "use_cut_node_roles"),
        ({"cuttable_segment_ids": "Bone"}, "cuttable_segment_ids"),
        ({"cuttable_segment_ids": ("Bone", "")}, "cuttable_segment_ids"),
        ({"mesh_model_node_id": ""}, "mesh_model_node_id"),
    ],
)
def test_invalid_parameters_name_the_field(changes, field):
    with pytest.raises(ToolConfigError) as raised:
        ToolParameters(**changes)
    assert raised.value.field == field
    assert str(raised.value).startswith(field + ":")


def test_parameters_match_the_node_defaults_and_limits():
    node = slicer.vtkMRMLVolumeCutToolNode()
    assert toolconfig.from_tool_node(node) == ToolParameters()
    assert toolconfig.diameter_range("DiskSaw") == (5.0, 60.0)
    assert ToolParameters(shape="DiskSaw", diameter=60.0).diameter == 60.0
    assert ToolParameters(cuttable_segment_ids=["a", "b", "a"]).cuttable_segment_ids == ("a", "b")


def test_apply_is_one_modification_and_mesh_tools_reference_their_model(application):
    scene = application.scene
    mesh = scene.AddNewNodeByClass("vtkMRMLModelNode", "Custom burr")
    tool = scene.AddNewNodeByClass("vtkMRMLVolumeCutToolNode", "Tool")
    modified = []
    tool.AddObserver("ModifiedEvent", lambda caller, event: modified.append(event))
    params = ToolParameters(shape="Mesh", burr_type="Diamond", power=0.25, speed=1000.0, use_cut_node_roles=False,
                            cuttable_segment_ids=("Bone",), mesh_model_node_id=mesh.GetID())
    toolconfig.apply_to_tool_node(params, tool)
    assert len(modified) == 1
    assert tool.GetMeshModelNode() is mesh
    assert toolconfig.from_tool_node(tool) == params
    with pytest.raises(RuntimeError, match="not a model node"):
        toolconfig.apply_to_tool_node(params.replace(mesh_model_node_id=tool.GetID()), tool)
    assert toolconfig.from_tool_node(tool) == params


def test_create_tool_node_leaves_nothing_behind_on_failure(application):
    scene = application.scene
    before = scene.GetNumberOfNodes()
    with pytest.raises(RuntimeError, match="not a model node"):
        toolconfig.create_tool_node(scene, ToolParameters(shape="Mesh", mesh_model_node_id="vtkMRMLModelNode999"), "Broken")
    assert scene.GetNumberOfNodes() == before
    bare = slicer.vtkMRMLScene()
    with pytest.raises(RuntimeError, match="no tool node classes"):
        toolconfig.create_tool_node(bare, ToolParameters())
    assert bare.GetNumberOfNodes() == 0


# ---------------------------------------------------------------- sensibility


@pytest.fixture
def cut_session(application):
    scene = application.scene
    segmentation = scene.AddNewNodeByClass("vtkMRMLSegmentationNode", "Anatomy")
    for segment_id, color in (("Mastoid", (0.9, 0.8, 0.6)), ("FacialNerve", (1.0, 1.0, 0.0)),
                              ("Sinus", (0.0, 0.0, 1.0)), ("Cortex", (1.0, 1.0, 1.0))):
        segmentation.GetSegmentation().AddEmptySegment(segment_id, segment_id + " segment", color)
    cut = scene.AddNewNodeByClass("vtkMRMLVolumeCutNode", "Cut")
    cut.SetAndObserveSegmentationNodeID(segmentation.GetID())
    assert cut.SetSegmentCuttable("Mastoid", True)
    assert cut.SetSegmentCuttable("Cortex", True)
    assert cut.SetSegmentProtected("FacialNerve", True)
    tool = toolconfig.create_tool_node(scene, PRESETS[0].parameters, "Burr")
    return cut, tool


def rows_by_id(cut, tool=None):
    return {row.segment_id: row for row in toolconfig.sensibility_rows(cut, tool)}


def test_sensibility_rows_follow_the_cut_node_roles(cut_session):
    cut, tool = cut_session
    rows = toolconfig.sensibility_rows(cut, tool)
    assert [row.segment_id for row in rows] == ["Mastoid", "FacialNerve", "Sinus", "Cortex"]
    by_id = {row.segment_id: row for row in rows}
    assert by_id["Mastoid"].name == "Mastoid segment"
    assert by_id["Mastoid"].color == pytest.approx((0.9, 0.8, 0.6))
    assert [by_id[s].role for s in ("Mastoid", "FacialNerve", "Sinus")] == ["cuttable", "protected", ""]
    assert [by_id[s].may_cut for s in ("Mastoid", "FacialNerve", "Sinus", "Cortex")] == [True, False, False, True]
    assert not any(row.from_tool for row in rows)
    assert not by_id["FacialNerve"].editable and by_id["Sinus"].editable
    # Roles change, rows follow.
    cut.SetSegmentProtected("Cortex", True)
    assert not rows_by_id(cut, tool)["Cortex"].may_cut
    # Without a tool: the roles alone; without a segmentation: no rows.
    assert rows_by_id(cut)["Mastoid"].may_cut
    assert toolconfig.sensibility_rows(slicer.vtkMRMLVolumeCutNode(), tool) == []


def test_a_tool_override_changes_one_segment_and_protection_wins(cut_session):
    cut, tool = cut_session
    toolconfig.set_segment_cuttable_for_tool(cut, tool, "Sinus", True)
    assert not tool.GetUseCutNodeRoles()
    by_id = rows_by_id(cut, tool)
    # The override starts from what the roles allowed, plus the change.
    assert [by_id[s].may_cut for s in ("Mastoid", "FacialNerve", "Sinus", "Cortex")] == [True, False, True, True]
    assert all(row.from_tool for row in by_id.values())
    toolconfig.set_segment_cuttable_for_tool(cut, tool, "Mastoid", False)
    assert not rows_by_id(cut, tool)["Mastoid"].may_cut
    assert rows_by_id(cut)["Mastoid"].may_cut  # the cut node's roles are untouched
    assert tuple(tool.GetCuttableSegmentIDs()) == ("Cortex", "Sinus")

    before = tuple(tool.GetCuttableSegmentIDs())
    with pytest.raises(ToolConfigError, match="'FacialNerve segment' is protected"):
        toolconfig.set_segment_cuttable_for_tool(cut, tool, "FacialNerve", True)
    with pytest.raises(ToolConfigError, match="'Dura' is not in the segmentation"):
        toolconfig.set_segment_cuttable_for_tool(cut, tool, "Dura", True)
    assert tuple(tool.GetCuttableSegmentIDs()) == before
    # Protecting a segment later takes it from the tool as well.
    cut.SetSegmentProtected("Sinus", True)
    assert not rows_by_id(cut, tool)["Sinus"].may_cut
    # Back to the cut node's roles.
    tool.SetUseCutNodeRoles(True)
    assert rows_by_id(cut, tool)["Mastoid"].may_cut


# ---------------------------------------------------------------- devices


def test_list_devices_gives_the_mouse_here():
    devices = toolconfig.list_devices()
    assert devices[0] == inputdevices.MOUSE_DEVICE
    assert devices[0].label.startswith("Mouse")
    assert all(device.kind in (inputdevices.MOUSE, inputdevices.HAPTIC, inputdevices.SIX_DOF, inputdevices.FOOT_SWITCH)
               for device in devices)


def test_missing_device_libraries_give_no_devices():
    assert inputdevices.list_hid_devices("libhidapi-missing.so.0") == []
    assert inputdevices.list_usb_devices("libusb-missing.so.0") == []


def umockdev_device(path, lines):
    path.write_text(textwrap.dedent(lines).lstrip())
    return path


@pytest.mark.skipif(shutil.which("umockdev-run") is None, reason="umockdev is not installed (apt-get install umockdev)")
def test_known_devices_are_listed_under_umockdev(tmp_path):
    """A SpaceMouse and a foot switch on hidraw, a Falcon and an unknown device on USB, all faked in user space."""
    usb = "/devices/pci0000:00/0000:00:14.0/usb1"

    def hidraw(port, vendor, product, name, serial, number):
        interface = f"{usb}/1-{port}/1-{port}:1.0"
        hid = f"{interface}/0003:{vendor:04X}:{product:04X}.000{number}"
        return f"""
            P: {usb}/1-{port}
            E: DEVTYPE=usb_device
            E: SUBSYSTEM=usb
            A: idVendor={vendor:04x}
            A: idProduct={product:04x}
            A: product={name}
            A: serial={serial}

            P: {interface}
            E: DEVTYPE=usb_interface
            E: SUBSYSTEM=usb
            A: bInterfaceNumber=00

            P: {hid}
            E: HID_ID=0003:0000{vendor:04X}:0000{product:04X}
            E: HID_NAME={name}
            E: HID_UNIQ={serial}
            E: SUBSYSTEM=hid

            P: {hid}/hidraw/hidraw{number}
            N: hidraw{number}
            E: DEVNAME=/dev/hidraw{number}
            E: SUBSYSTEM=hidraw
            """

    def raw_usb(port, address, vendor, product):
        # Device descriptor, then a configuration with one interface and two bulk endpoints.
        device = struct.pack("<BBHBBBBHHHBBBB", 18, 1, 0x0200, 0, 0, 0, 8, vendor, product, 0x0100, 1, 2, 3, 1)
        descriptor = device.hex().upper() + "090220000101008032090400000002FFFFFF02070581024000000705020240000000"
        return f"""
            P: {usb}/1-{port}
            N: bus/usb/001/{address:03d}
            E: DEVNAME=/dev/bus/usb/001/{address:03d}
            E: DEVTYPE=usb_device
            E: SUBSYSTEM=usb
            A: busnum=1
            A: devnum={address}
            A: idVendor={vendor:04x}
            A: idProduct={product:04x}
            A: bConfigurationValue=1
            H: descriptors={descriptor}
            """

    files = [
        umockdev_device(tmp_path / "spacemouse.umockdev", hidraw(2, 0x256F, 0xC62E, "SpaceMouse Wireless", "SM0001", 0)),
        umockdev_device(tmp_path / "pedal.umockdev", hidraw(4, 0x05F3, 0x00FF, "VEC USB Footpedal", "", 1)),
        umockdev_device(tmp_path / "keyboard.umockdev", hidraw(5, 0x046D, 0xC31C, "USB Keyboard", "", 2)),
        umockdev_device(tmp_path / "falcon.umockdev", raw_usb(3, 5, 0x0403, 0xCB48)),
        umockdev_device(tmp_path / "serial.umockdev", raw_usb(6, 7, 0x0403, 0x6001)),
    ]
    probe = ("import json; from VolumeCuttingLib.config import inputdevices as d; "
             "print(json.dumps([[x.device_id, x.kind, x.backend, x.vendor_id, x.product_id, x.serial_number] for x in d.list_devices()]))")
    command = ["umockdev-run"] + [f"--device={f}" for f in files] + ["--", sys.executable, "-c", probe]
    result = subprocess.run(command, cwd=LIBRARY_DIR.parent, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    devices = json.loads(result.stdout.strip().splitlines()[-1])
    assert devices[0][:3] == ["mouse", "mouse", "virtual"]
    listed = sorted(map(tuple, devices[1:]))
    assert listed == sorted([
        ("/dev/hidraw0", "6dof", "hidapi", 0x256F, 0xC62E, "SM0001"),
        ("/dev/hidraw1", "footswitch", "hidapi", 0x05F3, 0x00FF, ""),
        ("usb:1:5", "haptic", "libusb", 0x0403, 0xCB48, ""),
    ])
