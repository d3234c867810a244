"""intervalkin: certified definition sets of the planar 3-RPR parallel manipulator.

The package follows Wenger & Chablat (1997), one module per concept, data flowing
one way:

geometry      the manipulator as exact, validated data (the paper's is the default)
interval      vectorized outward-rounded interval arithmetic; the bridge to arb
kinematics    g, A and det A: float, interval (natural and centred forms) and arb
"""

from .errors import GeometryError, InputError, IntervalkinError, ResourceError
from .geometry import Geometry, Surd, default_geometry, load_geometry
from .interval import Interval

__all__ = [
    "IntervalkinError",
    "GeometryError",
    "InputError",
    "ResourceError",
    "Geometry",
    "Surd",
    "default_geometry",
    "load_geometry",
    "Interval",
]

__version__ = "0.1.0"
