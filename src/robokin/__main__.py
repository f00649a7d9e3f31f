"""``python -m robokin``."""

import sys

from robokin.cli import main

sys.exit(main())
