"""The instructor link's test hook: the cut's checksum only with --test-hooks, and hashing only what changed.

``vc_co_checksum`` lets the browser tests show that a refused page changed
nothing. It used to hash every sample of the cut field at each call, for any
page that joined: on a large cut, a page could keep the server busy. Now the
trigger exists only when the server runs with ``--test-hooks``, and
``CutDigest`` hashes only the bricks written since its last call.
"""

from __future__ import annotations

import hashlib
from types import SimpleNamespace

import numpy as np
import pytest
import slicer
import vtk
from trame.app import get_server

from VolumeCuttingLib.webapp import app, instructorlink


class CountingField:
    """A cut field whose CopyBrick calls are counted (the digest's cost)."""

    def __init__(self, field):
        self.field = field
        self.copied = 0

    def CopyBrick(self, brick, values):
        self.copied += 1
        return self.field.CopyBrick(brick, values)

    def __getattr__(self, name):
        return getattr(self.field, name)


def field_with_hole():
    matrix = vtk.vtkMatrix4x4()
    for axis in range(3):
        matrix.SetElement(axis, axis, 0.5)
    field = slicer.vtkVolumeCutField()
    assert field.Initialize([48, 48, 48], matrix, 1)
    field.BeginStroke()
    assert field.CutCapsule([6.0, 6.0, 6.0], [18.0, 6.0, 6.0], 3.0)
    field.EndStroke()
    return field


def every_sample_digest(field) -> str:
    """What the digest must equal: the same brick-by-brick hash, computed from scratch."""
    digest = hashlib.sha256()
    values = np.zeros(512, dtype=np.int16)
    for n in range(field.GetNumberOfAllocatedBricks()):
        brick = field.GetAllocatedBrickId(n)
        field.CopyBrick(brick, values)
        if not np.all(values == instructorlink.CutDigest.FAR_OUTSIDE):
            digest.update(int(brick).to_bytes(8, "little") + hashlib.sha256(values.tobytes()).digest())
    return digest.hexdigest()


def test_the_digest_follows_the_cut_and_hashes_only_the_bricks_written_since_its_last_call():
    field = field_with_hole()
    counted = CountingField(field)
    digest = instructorlink.CutDigest()
    first = digest.hexdigest(counted)
    assert first == every_sample_digest(field) and counted.copied == field.GetNumberOfAllocatedBricks() > 20
    counted.copied = 0
    assert digest.hexdigest(counted) == first and counted.copied == 0  # nothing changed: nothing hashed

    stamp = field.GetCurrentStamp()
    field.BeginStroke()
    assert field.CutCapsule([20.0, 18.0, 6.0], [20.0, 19.0, 6.0], 1.0)  # a small stroke elsewhere
    field.EndStroke()
    changed = vtk.vtkIdList()
    field.GetBricksModifiedSince(stamp, changed)
    second = digest.hexdigest(counted)
    assert second != first and second == every_sample_digest(field)
    assert 0 < counted.copied == changed.GetNumberOfIds() < field.GetNumberOfAllocatedBricks() // 4

    assert field.Undo()
    assert digest.hexdigest(counted) == first  # the undo restored the cut bit for bit


@pytest.mark.parametrize("hooks", [False, True])
def test_the_checksum_trigger_exists_only_with_test_hooks(hooks):
    server = get_server(f"cut-digest-hooks-{hooks}", client_type="vue3")
    instructorlink.InstructorLink(SimpleNamespace(server=server, options=app.Options(test_hooks=hooks)))
    assert ("vc_co_checksum" in server.controller._triggers) is hooks
    assert "vc_co_freeze" in server.controller._triggers


def test_the_option_is_off_unless_asked_for():
    import argparse

    parser = argparse.ArgumentParser()
    app.add_arguments(parser)
    assert app.options_from_arguments(parser.parse_args(["--phantom"])).test_hooks is False
    assert app.options_from_arguments(parser.parse_args(["--phantom", "--test-hooks"])).test_hooks is True
