"""``python -m robokin.cli`` (as ``python -m robokin``)."""

import sys

from robokin.cli.entry import main

sys.exit(main())
