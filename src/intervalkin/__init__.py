"""intervalkin: certified definition sets of the planar 3-RPR parallel manipulator.

The package follows Wenger & Chablat (1997), one module per concept, data flowing
one way (each module imports only modules above it in this list):

geometry      the manipulator as exact, validated data (the paper's is the default)
interval      vectorized outward-rounded interval arithmetic; the bridge to arb
kinematics    g, A and det A: float (approx_*), interval (natural and centred forms), arb
paving        octree pavings: tri-state labels, subdivision, face adjacency with the phi seam
checker       the independent verifier of certificates (geometry + arb only)
dkp           certified direct kinematics: every solution, proved unique, completeness proved
predicates    W, the sign of det A and the aspects as tri-state labels over arrays of boxes
export        atomic npz / JSON / VTK writers          figures   PNG renderings
joint         joint space: outer enclosure of g(S), cells of certified solution count
continuation  certified tracking of solutions along joint-space paths (sheets of a cell)
regions       characteristic surfaces, basic regions, basic components, uniqueness domains
certificates  claim files written from the results above
trajectory    certified non-singular assembly-mode changing paths
analysis      the whole chain for one geometry, writing one output folder
paper         the paper's Table 1, counts and report, regenerated and compared
cli           the ``intervalkin`` command
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

#: Default octree depth of ``intervalkin analyze`` / ``paper`` (about a minute on two cores).
DEFAULT_DEPTH = 8
