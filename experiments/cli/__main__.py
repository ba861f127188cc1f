"""``python -m ddmm.experiments.cli``: the ``ddmm`` command line."""

import sys

from ddmm.experiments.cli.app import main

sys.exit(main())
