"""How much of an answer is proved: a status, and counts with their bounds.

Every result of the library says what it proves.  :class:`Status` is the
verdict on one answer:

* ``CERTIFIED``: proved (a label, a cell count, an exact count);
* ``LOWER_BOUND``: a count of which only a lower bound is proved;
* ``UNDECIDED``: nothing is proved (the question falls in the undecided layer
  at this depth, or a certified solve could not be completed).

:class:`Count` is the number of connected pieces of one kind (aspects, basic
regions, uniqueness domains): the number found at this depth with the bounds
that are proved around it.  Its checks are the contract: ``lower <= found``,
``found <= upper`` when an upper bound is proved, and ``exact`` exactly when the
two bounds meet.

>>> c = Count(found=28, lower=12, upper=None, exact=False, why="sheets above the joint cells")
>>> c.status
<Status.LOWER_BOUND: 'lower bound'>
>>> c.to_json()["lower_bound"], c.to_json()["upper_bound"]
(12, None)
>>> Count(found=2, lower=3, upper=None, exact=False, why="")
Traceback (most recent call last):
...
ValueError: count: found 2 is below the certified lower bound 3
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

__all__ = ["Status", "Count"]


class Status(enum.Enum):
    """Verdict on one answer: proved, proved from below only, or not proved."""

    CERTIFIED = "certified"
    LOWER_BOUND = "lower bound"
    UNDECIDED = "undecided"


@dataclass(frozen=True)
class Count:
    """A number of pieces found, with its certified bounds.

    Attributes
    ----------
    found : int
        The number found at this depth (never below ``lower``).
    lower : int
        Certified lower bound: that many pieces are proved pairwise different.
    upper : int or None
        Certified upper bound; None when none is proved.
    exact : bool
        True exactly when ``lower == upper`` (then ``found`` is the true number).
    why : str
        What backs the bounds, and what is missing for an exact count.
    undecided : dict
        Where the bounds could not be closed (volumes, boxes, places); empty when nothing is said.
    """

    found: int
    lower: int
    upper: int | None
    exact: bool
    why: str
    #: what keeps the bounds apart: where and how much is undecided (empty when nothing is said)
    undecided: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("found", "lower", "upper"):
            v = getattr(self, name)
            if v is None and name == "upper":
                continue
            if isinstance(v, bool) or not isinstance(v, int) or v < 0:
                raise ValueError(f"count: {name} must be a non-negative integer, got {v!r}")
        if self.found < self.lower:
            raise ValueError(f"count: found {self.found} is below the certified lower bound {self.lower}")
        if self.upper is not None and self.found > self.upper:
            raise ValueError(f"count: found {self.found} is above the certified upper bound {self.upper}")
        if self.exact != (self.upper is not None and self.upper == self.lower):
            raise ValueError(f"count: exact={self.exact} but the bounds are {self.lower}..{self.upper}")

    @property
    def status(self) -> Status:
        """CERTIFIED when exact, LOWER_BOUND when a positive lower bound is proved, else UNDECIDED."""
        if self.exact:
            return Status.CERTIFIED
        return Status.LOWER_BOUND if self.lower > 0 else Status.UNDECIDED

    def to_json(self) -> dict:
        """The summary.json block: ``count``, ``exact``, ``lower_bound``, ``upper_bound`` (null: none proved), ``why``."""
        return {"count": self.found, "exact": self.exact, "lower_bound": self.lower,
                "upper_bound": self.upper, "why": self.why,
                # issue 14's names for the same numbers
                "found": self.found, "lower": self.lower, "upper": self.upper, "undecided": dict(self.undecided)}
