"""The PUMA 762 in closed form: forward and reverse (inverse) position analysis, batched.

Crane–Duffy convention (Vibhute 2011 §2.2; Crane & Duffy 1998 ch. 10): frame j has z along the
joint axis S_j and x along the common normal a_jk; frame j is placed in frame i by
``Rx(α_ij) · Tx(a_ij) · Rz(θ_j) · Tz(S_j)`` (eq. 2-26) and the fixed frame F shares frame 1's
origin and z axis, ``F_1T = Rz(φ1)`` (eq. 2-28). Joint values are ``q = (φ1, θ2, θ3, θ4, θ5, θ6)``
in radians. Mechanism parameters (Tables 2-2 and 2-3, millimetres)::

    a12 = 0    α12 = 90°
    a23 = 650  α23 = 0     S2 = 190
    a34 = 0    α34 = 270°  S3 = 0
    a45 = 0    α45 = 90°   S4 = 600
    a56 = 0    α56 = 90°   S5 = 0
               α67 = 90°   S6 = 125

The end effector is described as the thesis does: the tool point ``P_tool_F`` (fixed frame), the
sixth joint axis ``S6_F`` (z of frame 6) and the link direction ``a67_F`` (x of frame 6); the tool
point's coordinates in frame 6 are ``P_tool_6``. The reverse analysis closes the loop with the
hypothetical seventh link (:func:`close_loop`) and solves φ1, θ3, θ2, θ5, θ4, θ6 in turn: two φ1 ×
two θ3 × two θ5 = eight branches, in the order of the solution tree (Figure 2-14): branch index
``4·i1 + 2·i3 + i5``. Branches that fall on a wrist singularity (sin θ5 = 0) are one-parameter
families (θ6 − θ4 fixed when θ5 = 0, θ4 + θ6 fixed when θ5 = 180°), reported as such.

The robot's axis angles differ from q by the thesis's kinematic correction (Appendix D.2,
``Pos_A_KCorrection``): axis 1 = φ1 + 180°, the others equal θ2..θ6; joint limits are applied to
axis angles (:data:`AXIS_LIMITS_DEG`).

The closed form is split by concept: :mod:`.params` (mechanism parameters, axis
conventions, status codes), :mod:`.forward` (forward analysis, the end effector as a frame),
:mod:`.reverse` (closing the loop, the eight branches, one pose's solutions and families),
:mod:`.selection` (axis angles, limits, least-motion choice); :mod:`._kernels` holds the
compiled kernels and :mod:`._reference` the NumPy reference used by the tests. This module
gathers every name (also importable from the deprecated ``kinestat.serial.puma762``).
"""

from __future__ import annotations

from kinestat.robots.puma762 import forward as _forward
from kinestat.robots.puma762 import params as _params
from kinestat.robots.puma762 import reverse as _reverse
from kinestat.robots.puma762 import selection as _selection
from kinestat.robots.puma762.forward import *  # noqa: F403 (re-exported: its __all__)
from kinestat.robots.puma762.params import *  # noqa: F403
from kinestat.robots.puma762.reverse import *  # noqa: F403
from kinestat.robots.puma762.selection import *  # noqa: F403

# the link table (cos α, sin α, a, S of links 1-2 .. 5-6), read by the tests
_CA, _SA, _A, _S = _params._CA, _params._SA, _params._A, _params._S

#: the theses' names: forward analysis = fk, reverse analysis = ik (closed form)
forward_analysis = _forward.forward
reverse_analysis = _reverse.reverse

__all__ = [
    *_params.__all__,
    *_forward.__all__,
    *_reverse.__all__,
    *_selection.__all__,
    "forward_analysis",
    "reverse_analysis",
]
