"""pytest configuration for the rendering tests: the analytic scene lives in VolumeCuttingLib."""

import sys
from pathlib import Path

LIBRARY_DIR = Path(__file__).resolve().parents[4] / "Scripted" / "VolumeCuttingTools"
if str(LIBRARY_DIR) not in sys.path:
    sys.path.insert(0, str(LIBRARY_DIR))
