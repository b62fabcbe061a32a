"""``python -m VolumeCuttingLib.webapp``: serve the drilling application (``Utilities/vc app``)."""

import sys

from .app import main

sys.exit(main())
