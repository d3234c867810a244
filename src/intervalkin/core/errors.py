"""Errors raised by intervalkin: one base class, one subclass per kind.

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


class CertificateFormatError(InputError):
    """A certificate folder is missing, unreadable or not in the documented format."""


class ResourceError(IntervalkinError):
    """A request would exceed what the machine can give (memory, depth)."""


class NoPathError(IntervalkinError):
    """No non-singular motion can be given: the two assembly modes are in different aspects
    (then none exists), or none was found through the certified boxes (not a proof that none exists)."""
