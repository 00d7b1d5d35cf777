"""``python -m liganimate``."""

import sys

from liganimate.cli import main

sys.exit(main())
