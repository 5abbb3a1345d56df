"""Which closed form a 6-joint chain admits, detected from its joint axes at q = 0.

In product-of-exponentials form ``T(q) = e^{ξ̂1 q1} ⋯ e^{ξ̂6 q6} T(0)`` (MLS eq. 3.26), joint i's
axis at q = 0 is the z axis of ``C0 C1 ⋯ C(i-1)``. Closed forms by subproblems need special
axis geometry:

- ``"pieper"``: axes 4, 5, 6 meet at one point (a spherical wrist, Pieper 1968). Axes 1, 2
  meeting (PUMA-type shoulders): subproblems 3, 2, 2, 1; an offset shoulder (KUKA, ABB,
  Fanuc): a quartic in θ3 (:mod:`kinestat.serial.analytic.pieper_offset`).
- ``"three-parallel"``: axes 2, 3, 4 parallel and axes 5, 6 meeting (UR-type): subproblems 4,
  4, 1, 1, 3, 1.
- ``"decoupled"``: prismatic joints among joints 1-3 and a spherical wrist (one univariate
  eliminant for the wrist centre, :mod:`kinestat.serial.analytic.decoupled`).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass

import numpy as np

from kinestat.errors import ModelError
from kinestat.mechanism.chain import ChainModel
from kinestat.spatial.transforms import cross3  # NumPy's cross costs ~10 µs a call

__all__ = ["HomeAxes", "home_axes", "meet", "parallel", "classify", "classify_axes", "cross3",
           "norm3", "PRESET", "DERIVED", "same_line_pairs", "check_independent"]


#: geometry classes found without :func:`classify`, by a caller that built the model from one
#: already classified (a locked arm's chain folded at a new value: its axes are the folded
#: chain's moved by the locked joint's turn): model -> ``(kind, data)``
PRESET: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

#: chains derived from an arm already checked by :func:`check_independent`: reversed, or
#: folded at locked values (:mod:`kinestat.serial.analytic.locked`), where a pair on one line
#: only at a locked value (the Panda's joints 1 and 3 at q2 = 0) is a singular value of the
#: arm, not joints that act as one (the arm's own consecutive pairs are checked before locking)
DERIVED: weakref.WeakSet = weakref.WeakSet()


@dataclass(frozen=True, eq=False, init=False)  # __init__ below: see there
class HomeAxes:
    """Joint axes at q = 0 in the base frame: directions ``w (n, 3)``, points ``r (n, 3)``, the
    home pose ``T0`` and a length scale of the model."""

    w: np.ndarray
    r: np.ndarray
    T0: np.ndarray
    scale: float

    def __init__(self, w: np.ndarray, r: np.ndarray, T0: np.ndarray, scale: float) -> None:
        # the dataclass's own __init__, written out (generating it costs a first ik_all call
        # a fifth of a millisecond): the fields above, in their order, frozen
        self.__dict__.update(w=w, r=r, T0=T0, scale=scale)


def home_axes(model: ChainModel) -> HomeAxes:
    """The joint axes of ``model`` at q = 0 (``F1 = C0``, ``F(i+1) = Fi Ci``)."""
    C = np.asarray(model.constants)
    F = C[0].copy()
    w, r = [], []
    for i in range(model.n):
        w.append(F[:3, 2].copy())
        r.append(F[:3, 3].copy())
        F = F @ C[i + 1]
    scale = max(1.0, float(np.max(np.abs(C[:, :3, 3]))))
    return HomeAxes(np.array(w), np.array(r), F, scale)


def norm3(a: np.ndarray) -> float:
    """The length of a 3-vector (as :func:`cross3`: without ``np.linalg.norm``'s overhead)."""
    return math.sqrt(float(a @ a))


def parallel(ax: HomeAxes, i: int, j: int, tol: float = 1e-9) -> bool:
    """Axes i and j are parallel (or anti-parallel)."""
    return norm3(cross3(ax.w[i], ax.w[j])) <= tol


def meet(ax: HomeAxes, i: int, j: int, tol: float = 1e-9):
    """The point where non-parallel axes i and j meet, or None."""
    wi, wj, d = ax.w[i], ax.w[j], ax.r[j] - ax.r[i]
    n = cross3(wi, wj)
    nn = float(n @ n)
    if nn <= tol ** 2:
        return None
    if abs(float(d @ n)) / np.sqrt(nn) > tol * ax.scale:
        return None
    # r_i + s wi = r_j + t wj  (least squares on the two-line system)
    s = float(cross3(d, wj) @ n) / nn
    return ax.r[i] + s * wi


def classify(model: ChainModel, tol: float = 1e-9) -> tuple[str, dict]:
    """``("pieper" | "three-parallel" | "general", data)`` for a 6-joint revolute model;
    ``("decoupled", data)`` for one with prismatic joints among joints 1-3 and a spherical
    wrist (:mod:`kinestat.serial.analytic.decoupled` checks the rest); ``("none", {})``
    otherwise."""
    kinds = [j.kind for j in model.joints]
    if model.n != 6 or "screw" in kinds or "prismatic" in kinds[3:]:
        return "none", {}
    return classify_axes(kinds, home_axes(model), tol)


def classify_axes(kinds: list[str], ax: HomeAxes, tol: float = 1e-9) -> tuple[str, dict]:
    """:func:`classify` from the joint kinds (six, none a screw, joints 4-6 revolute) and
    the axes at q = 0."""
    w = meet(ax, 3, 4, tol)
    spherical = w is not None and \
        norm3(cross3(w - ax.r[5], ax.w[5])) <= tol * ax.scale
    if "prismatic" in kinds:
        return ("decoupled", {"axes": ax, "wrist": w}) if spherical else ("none", {})
    if spherical:  # shoulder: where axes 1, 2 meet, None for an offset shoulder
        return "pieper", {"axes": ax, "wrist": w, "shoulder": meet(ax, 0, 1, tol)}
    if parallel(ax, 1, 2, tol) and parallel(ax, 1, 3, tol):
        p56 = meet(ax, 4, 5, tol)
        if p56 is not None and not parallel(ax, 0, 1, tol) and not parallel(ax, 4, 1, tol):
            return "three-parallel", {"axes": ax, "p56": p56}
    return "general", {"axes": ax}


def same_line_pairs(model: ChainModel, tol: float = 1e-9) -> list[tuple[int, int]]:
    """Consecutive joints ``(i, i + 1)`` that act as one: two revolute joints about one line,
    or two prismatic joints along parallel lines. The axis of joint i + 1 is fixed in the link
    joint i moves, so a pair on one line at q = 0 stays so at every q: only ``q_i ± q_(i+1)``
    counts, the chain has a degree of freedom fewer than joints, and no pose has isolated IK
    solutions (a gripper's spin joint after a wrist roll; an R-P pair on one line is a
    cylindrical joint and counts twice)."""
    ax = home_axes(model)
    kinds = [j.kind for j in model.joints]
    out = []
    for i in range(model.n - 1):
        if kinds[i] != kinds[i + 1] or kinds[i] not in ("revolute", "prismatic"):
            continue
        if not parallel(ax, i, i + 1, tol):
            continue
        off = norm3(cross3(ax.r[i + 1] - ax.r[i], ax.w[i]))
        if kinds[i] == "prismatic" or off <= tol * ax.scale:
            out.append((i, i + 1))
    return out


def check_independent(model: ChainModel, what: str = "ik_all", held=()) -> None:
    """A ModelError naming the first pair of :func:`same_line_pairs` of ``model`` (neither of
    them among the ``held`` joints, 0-based), if any."""
    pairs = [p for p in same_line_pairs(model) if p[0] not in held and p[1] not in held]
    if not pairs:
        return
    i, k = pairs[0]
    names = f" ({model.joints[i].name!r}, {model.joints[k].name!r})" \
        if model.joints[i].name and model.joints[k].name else ""
    how = "turn about one line" if model.joints[i].kind == "revolute" else \
        "slide along parallel lines"
    raise ModelError(
        f"{what}: joints {i + 1} and {k + 1}{names} of model {model.name!r} {how}: only their "
        f"sum (or difference) counts, so every pose's solutions form a continuum, not "
        f"isolated solutions; end the chain before joint {k + 1} (a URDF's tip=, --tip), lock "
        f"one of them (locked=, --lock) on a longer arm, or use kinestat.ik for one solution")
