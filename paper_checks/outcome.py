"""What a check returns: an :class:`Outcome` whose verdict is one of :data:`VERDICTS`.

The verdicts are described in :mod:`paper_checks.audit`, which runs the
checks and re-exports both names; the check modules' helpers
(:mod:`paper_checks._common`) build outcomes without importing the runner.
"""

import dataclasses

__all__ = ["VERDICTS", "Outcome"]

VERDICTS = ("confirmed", "erratum", "approximation", "not-reproduced", "not-checkable")


@dataclasses.dataclass(frozen=True)
class Outcome:
    """What a check found: a verdict, one or two lines of evidence, a fix."""

    verdict: str
    evidence: str
    corrected: str = ""

    def __post_init__(self):
        if self.verdict not in VERDICTS:
            raise ValueError(f"verdict must be one of {VERDICTS}, got {self.verdict!r}")
        if self.verdict == "erratum" and not self.corrected:
            raise ValueError("an erratum must state the corrected form")
