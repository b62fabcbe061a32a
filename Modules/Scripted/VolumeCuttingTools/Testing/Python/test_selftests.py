"""The Slicer self-tests (VolumeCuttingLib.jobs.selftests) under pytest, against slicer-core.

Desktop Slicer runs the same cases as the VolumeCuttingTools module's self-test.
"""

import pytest

from VolumeCuttingLib.jobs import selftests
from VolumeCuttingLib.scene.application import HeadlessSlicer


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(selftests.CASES))
def test_self_test_case(name, tmp_path):
    application = HeadlessSlicer()
    context = selftests.SelfTestContext(application.scene, application.volume_cutting_logic, tmp_path)
    figures = selftests.CASES[name](context)
    assert figures
