"""``python -m rvdyn``: the same command line as the ``rvdyn`` console script."""

import sys

from rvdyn.cli import main

sys.exit(main())
