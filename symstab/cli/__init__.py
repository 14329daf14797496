"""The ``symstab`` command line (a front end: it may use every layer and
``paper_checks``).
"""

from .commands import main

__all__ = ["main"]
