"""kinestat: kinematics and statics (kinestatics) of robot manipulators.

The stable top-level API::

    import kinestat
    model = kinestat.load("puma762")          # an embedded model or a TOML file
    T = kinestat.fk(model, q)                 # (..., 4, 4) for q of shape (..., n)
    J = kinestat.jacobian(model, q)           # (..., 6, n), twists [w; v_O]
    res = kinestat.ik(model, poses)           # numerical IK, batched, honest success flags
"""

from kinestat.errors import KinestatError
from kinestat.mechanism.chain import ChainModel
from kinestat.mechanism.library import list_models, load
from kinestat.serial.analytic import ik_all as ik_all
from kinestat.serial.fk import fk
from kinestat.serial.ik import ik
from kinestat.serial.jacobian import jacobian

__version__ = "0.1.0"

__all__ = [
    "ChainModel", "KinestatError", "load", "list_models", "fk", "jacobian", "ik", "__version__",
]
