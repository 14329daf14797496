"""``python -m symstab``: the same as the ``symstab`` command."""

import sys

from .cli.commands import main

sys.exit(main())
