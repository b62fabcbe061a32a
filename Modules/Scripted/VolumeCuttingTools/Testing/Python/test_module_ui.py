"""The desktop module's widget file against its .ui, without Qt.

Desktop Slicer is not available here, so the checks that can be made without
it are made statically: the module compiles, every ``SlicerParameterName`` in
the .ui is a parameter of the parameter node, every ``self.ui.<name>``
the widget uses is a widget of the .ui, and what it asks of the Qt-free
controllers (the nerve monitor's meter and drill sound, the drilling
session, the instructor coupling and its status snapshot) exists there.
"""

import ast
import re
import py_compile
import xml.etree.ElementTree as ElementTree
from pathlib import Path

MODULE_DIR = Path(__file__).resolve().parents[2]
MODULE_FILE = MODULE_DIR / "VolumeCuttingTools.py"
CMAKE_FILE = MODULE_DIR / "CMakeLists.txt"
UI_FILE = MODULE_DIR / "Resources" / "UI" / "VolumeCuttingTools.ui"


def parameter_names():
    tree = ast.parse(MODULE_FILE.read_text())
    parameter_class = next(node for node in tree.body if isinstance(node, ast.ClassDef) and node.name == "VolumeCuttingToolsParameterNode")
    return {statement.target.id for statement in parameter_class.body if isinstance(statement, ast.AnnAssign)}


def ui_widgets():
    root = ElementTree.parse(UI_FILE).getroot()
    widgets = {}
    for widget in root.iter("widget"):
        bound = None
        for prop in widget.findall("property"):
            if prop.get("name") == "SlicerParameterName":
                bound = prop.findtext("string")
        widgets[widget.get("name")] = (widget.get("class"), bound)
    return widgets


def test_module_compiles(tmp_path):
    py_compile.compile(str(MODULE_FILE), cfile=str(tmp_path / "module.pyc"), doraise=True)


def test_ui_parameters_exist_in_the_parameter_node():
    parameters = parameter_names()
    bound = {name: parameter for name, (_, parameter) in ui_widgets().items() if parameter}
    assert set(bound.values()) <= parameters, set(bound.values()) - parameters
    # Each parameter is shown by one widget at most.
    assert len(set(bound.values())) == len(bound)
    for parameter in ("toolPreset", "toolShape", "burrType", "toolDiameter", "toolPower", "toolSpeed", "cutNode", "toolNode",
                      "couplingPort", "couplingPeer", "couplingFromOtherMachines"):
        assert parameter in bound.values()


def test_widgets_the_module_uses_are_in_the_ui():
    used = {node.attr for node in ast.walk(ast.parse(MODULE_FILE.read_text()))
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Attribute) and node.value.attr == "ui"}
    assert used, "no self.ui.<widget> found: the check would prove nothing"
    assert used <= set(ui_widgets()), used - set(ui_widgets())


def attributes_used_on(owner: str) -> set:
    """The names the module reads from ``<...>.<owner>.<name>`` or ``<owner>.<name>``."""
    used = set()
    for node in ast.walk(ast.parse(MODULE_FILE.read_text())):
        if isinstance(node, ast.Attribute):
            value = node.value
            if (isinstance(value, ast.Attribute) and value.attr == owner) or (isinstance(value, ast.Name) and value.id == owner):
                used.add(node.attr)
    return used


def test_the_instructor_coupling_group_is_in_the_ui():
    """Off / trainee (port, from other machines) / instructor (HOST:PORT), Start/Stop and the status line."""
    widgets = ui_widgets()
    expected = {
        "couplingGroupBox": ("QGroupBox", None),
        "couplingOffRadioButton": ("QRadioButton", None),
        "couplingTraineeRadioButton": ("QRadioButton", None),
        "couplingInstructorRadioButton": ("QRadioButton", None),
        "couplingPortSpinBox": ("QSpinBox", "couplingPort"),
        "couplingFromOtherMachinesCheckBox": ("QCheckBox", "couplingFromOtherMachines"),
        "couplingPeerLineEdit": ("QLineEdit", "couplingPeer"),
        "couplingButton": ("QPushButton", None),
        "couplingStatusLabel": ("QLabel", None),
    }
    assert {name: widgets.get(name) for name in expected} == expected
    # In the haptic (tool) section, below the Drill button.
    tool_section = next(w for w in ElementTree.parse(UI_FILE).getroot().iter("widget") if w.get("name") == "toolCollapsibleButton")
    inside = {w.get("name") for w in tool_section.iter("widget")}
    assert set(expected) <= inside and "drillButton" in inside


def test_the_coupling_roles_are_the_controllers():
    """The parameter node's roles are the controller's, one radio button each."""
    from VolumeCuttingLib.collaboration import desktopcoupling

    source = MODULE_FILE.read_text()
    assert "Choice(list(desktopcoupling.ROLES))" in source
    assert desktopcoupling.ROLES == (desktopcoupling.OFF, desktopcoupling.TRAINEE, desktopcoupling.INSTRUCTOR)
    for role, radio in (("OFF", "couplingOffRadioButton"), ("TRAINEE", "couplingTraineeRadioButton"),
                        ("INSTRUCTOR", "couplingInstructorRadioButton")):
        assert f"desktopcoupling.{role}: self.ui.{radio}" in source, role


def test_the_widget_asks_the_desktop_controllers_only_for_what_they_have():
    from VolumeCuttingLib.collaboration import desktopcoupling
    from VolumeCuttingLib.config import hapticdrilling
    from VolumeCuttingLib.feedback import desktopfeedback

    feedback = desktopfeedback.DesktopFeedback(logic=None)
    for owner, provided in (("_feedback", set(dir(feedback))), ("desktopfeedback", set(dir(desktopfeedback))),
                            ("_drilling", set(dir(hapticdrilling.HapticDrilling(logic=None)))),
                            ("_coupling", set(dir(desktopcoupling.DesktopCoupling()))),
                            ("desktopcoupling", set(dir(desktopcoupling))),
                            ("snapshot", set(dir(desktopcoupling.CouplingSnapshot())))):
        used = attributes_used_on(owner)
        assert used, f"the widget uses nothing of {owner}: the check would prove nothing"
        assert used <= provided, (owner, used - provided)
    # The meter is drawn from the rows' keys.
    rows = desktopfeedback.nervemonitor.meter_rows({"Nerve": {"distance_mm": 1.5, "level": "bursts", "firing_rate_hz": 10.0}})
    source = MODULE_FILE.read_text()
    for key in rows[0]:
        assert f'row["{key}"]' in source or f"row['{key}']" in source, key


# The web application needs trame-slicer: desktop Slicer does not get it, nor the benchmark area that drives it.
# What needs trame-slicer (the web app) or SQLAlchemy and Alembic (the trainee records), which Slicer does not ship.
NOT_IN_DESKTOP_SLICER = ("VolumeCuttingLib/webapp/", "VolumeCuttingLib/benchmarks/webapp.py", "VolumeCuttingLib/records/",
                         "VolumeCuttingLib/benchmarks/records.py", "VolumeCuttingLib/benchmarks/assessment.py")


def test_the_slicer_build_installs_every_library_module():
    """Desktop Slicer gets only what MODULE_PYTHON_SCRIPTS lists; a module left out fails to import there."""
    listed = set(re.findall(r"VolumeCuttingLib/[\w/]+\.py", CMAKE_FILE.read_text()))
    present = {path.relative_to(MODULE_DIR).as_posix() for path in (MODULE_DIR / "VolumeCuttingLib").rglob("*.py")}
    present = {name for name in present if not name.startswith(NOT_IN_DESKTOP_SLICER)}
    assert present, "no library modules found: the check would prove nothing"
    assert present <= listed, present - listed
    assert listed <= present, listed - present
