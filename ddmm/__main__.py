"""``python -m ddmm``: the ``ddmm`` command line."""

import sys

from ddmm.experiments.cli import main

sys.exit(main())
