"""Errors raised by intervalkin.

Every error a user can provoke (bad input, an impossible request) derives from
:class:`IntervalkinError`; the command line catches that base class, prints its
one-line message and exits with status 2.  Anything else is an internal failure
(exit status 1).
"""

from __future__ import annotations


class IntervalkinError(Exception):
    """Base class of the errors a user can provoke."""


class GeometryError(IntervalkinError):
    """A geometry description is malformed or describes an impossible manipulator."""


class InputError(IntervalkinError):
    """A value given by the user (joint vector, depth, path) is not acceptable."""


class ResourceError(IntervalkinError):
    """A request would exceed what the machine can give (memory, depth)."""
