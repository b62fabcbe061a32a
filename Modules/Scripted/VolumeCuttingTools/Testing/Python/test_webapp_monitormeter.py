"""The nerve-monitor meter rows (shown by the web application and the desktop widget) and the web 3D tint by level."""

import pytest
import slicer
import vtk

from VolumeCuttingLib.feedback import nervemonitor
from VolumeCuttingLib.webapp import monitormeter


def reading(distance, level):
    return {"distance_mm": distance, "level": level, "firing_rate_hz": 0.0}


def test_rows_carry_the_distance_its_bar_over_0_to_8_mm_and_the_level_colour():
    rows = nervemonitor.meter_rows({"FacialNerve": reading(2.0, "bursts"), "Stapes": reading(12.5, "silent"),
                                    "Incus": reading(None, "not ready"), "Malleus": reading(-0.3, "contact")})
    by_name = {row["name"]: row for row in rows}
    assert by_name["FacialNerve"] == {"name": "FacialNerve", "mm": 2.0, "bar": 0.25, "level": "bursts",
                                      "colour": nervemonitor.LEVEL_COLOURS["bursts"]}
    assert by_name["Stapes"]["bar"] == 1.0  # beyond full scale: a full bar
    assert by_name["Incus"]["mm"] is None and by_name["Incus"]["colour"] == nervemonitor.NOT_READY_COLOUR
    assert by_name["Malleus"]["bar"] == 0.0
    # Before its fields are built the monitor reads 0 mm, not ready: no figure then.
    assert nervemonitor.meter_rows({"Incus": reading(0.0, "not ready")})[0]["mm"] is None


def test_rows_are_sent_only_for_a_change_over_0_05_mm_or_of_level():
    shown = nervemonitor.meter_rows({"FacialNerve": reading(3.0, "sparse clicks")})
    assert not nervemonitor.rows_differ(shown, nervemonitor.meter_rows({"FacialNerve": reading(3.04, "sparse clicks")}))
    assert nervemonitor.rows_differ(shown, nervemonitor.meter_rows({"FacialNerve": reading(3.06, "sparse clicks")}))
    assert nervemonitor.rows_differ(shown, nervemonitor.meter_rows({"FacialNerve": reading(3.0, "bursts")}))
    assert nervemonitor.rows_differ(shown, nervemonitor.meter_rows({"FacialNerve": reading(None, "not ready")}))
    assert nervemonitor.rows_differ([], shown)


def test_colours_convert_both_ways_and_a_bad_one_is_refused():
    assert monitormeter.rgb_to_hex(monitormeter.hex_to_rgb("#ffab91")) == "#ffab91"
    with pytest.raises(ValueError, match="#rrggbb"):
        monitormeter.hex_to_rgb("red")


@pytest.fixture()
def segmentation_node():
    scene = slicer.vtkMRMLScene()
    node = scene.AddNewNodeByClass("vtkMRMLSegmentationNode")
    for name, colour in (("FacialNerve", (1.0, 1.0, 0.0)), ("Stapes", (0.5, 0.5, 0.9))):
        segment = slicer.vtkSegment()
        segment.SetName(name)
        segment.SetColor(*colour)
        image = slicer.vtkOrientedImageData()
        image.SetDimensions(4, 4, 4)
        image.AllocateScalars(vtk.VTK_UNSIGNED_CHAR, 1)
        image.GetPointData().GetScalars().Fill(1)
        segment.AddRepresentation("Binary labelmap", image)
        node.GetSegmentation().AddSegment(segment, name)
    return node


def test_a_segment_above_silent_takes_the_level_colour_and_gets_its_own_back(segmentation_node):
    segmentation = segmentation_node.GetSegmentation()
    nerve = segmentation.GetSegment("FacialNerve")
    labelmap_time = nerve.GetRepresentation("Binary labelmap").GetMTime()
    segmentation_time = segmentation.GetMTime()
    tint = monitormeter.SegmentTint()
    assert not tint.apply(segmentation_node, {"FacialNerve": "silent", "Stapes": "not ready"})
    assert tint.apply(segmentation_node, {"FacialNerve": "bursts", "Stapes": "silent"})
    assert nerve.GetColor() == pytest.approx(monitormeter.hex_to_rgb(nervemonitor.LEVEL_COLOURS["bursts"]))
    assert segmentation.GetSegment("Stapes").GetColor() == pytest.approx((0.5, 0.5, 0.9))
    assert tint.own_colour("FacialNerve", None) == pytest.approx((1.0, 1.0, 0.0))
    assert not tint.apply(segmentation_node, {"FacialNerve": "bursts"})  # nothing new: the view is not told
    assert tint.apply(segmentation_node, {"FacialNerve": "contact"})
    assert nerve.GetColor() == pytest.approx(monitormeter.hex_to_rgb(nervemonitor.LEVEL_COLOURS["contact"]))
    assert tint.apply(segmentation_node, {"FacialNerve": "silent"})
    assert nerve.GetColor() == pytest.approx((1.0, 1.0, 0.0))
    assert tint.tinted == {}
    # A colour is no labelmap: the cut field's and the monitor's inputs stay as they were.
    # (the 3D view's label volume is keyed on the segmentation's time: it is not rebuilt for a tint).
    assert nerve.GetRepresentation("Binary labelmap").GetMTime() == labelmap_time
    assert segmentation.GetMTime() == segmentation_time


def test_restore_gives_every_tinted_segment_its_own_colour(segmentation_node):
    tint = monitormeter.SegmentTint()
    tint.apply(segmentation_node, {"FacialNerve": "continuous", "Stapes": "sparse clicks"})
    assert tint.restore()
    segmentation = segmentation_node.GetSegmentation()
    assert segmentation.GetSegment("FacialNerve").GetColor() == pytest.approx((1.0, 1.0, 0.0))
    assert segmentation.GetSegment("Stapes").GetColor() == pytest.approx((0.5, 0.5, 0.9))
    assert not tint.restore()


def test_a_segment_no_longer_read_gets_its_own_colour_back(segmentation_node):
    tint = monitormeter.SegmentTint()
    tint.apply(segmentation_node, {"FacialNerve": "bursts", "Stapes": "bursts"})
    assert tint.restore_except({"FacialNerve": "bursts"})
    segmentation = segmentation_node.GetSegmentation()
    assert segmentation.GetSegment("Stapes").GetColor() == pytest.approx((0.5, 0.5, 0.9))
    assert sorted(tint.tinted) == ["FacialNerve"]
