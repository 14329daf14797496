"""``python -m symstab``: the same as the ``symstab`` command."""

import sys

from .cli import main

sys.exit(main())
