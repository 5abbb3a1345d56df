"""A 7R arm with a joint in between locked where a general 6R remains: the general 6R kernel's
arrays for a new value of the joint in a few µs, without a new chain.

Joint j locked at v folds ``C(j) Z(v) C(j+1)`` into one constant, affine in ``(1, cos v,
sin v)``. So is every array the compiled kernel of
:mod:`~kinestat.serial.analytic.general6r` takes from the chain: the constants, the links
(the folded one, or its inverse ``C(j+1)⁻¹ Z(−v) C(j)⁻¹``), and the left tensor L of RR eq. 4
with ``L H3``: the invariants' rigid action is a representation,
``rigid_action(A Z(v) B) = rigid_action(A) (D0 + cos v Dc + sin v Ds) rigid_action(B)``
(:func:`~kinestat.serial.analytic._rr_algebra.joint_basis`), and the folded link enters L's
product once. Three folds (v = 0, π/2, π) give the terms once per joint; a new value is then
one pass of ~3000 multiply-adds, where folding, classifying, choosing the formulation and
building L take ~2 ms. The spurious subspace's basis is left to the kernel (found per pose).

Which values share the geometry: the axes after joint j turn about it, and for an axis pair
across j, ``n = wa × wb``, ``(rb − ra) · n`` (the lines' reciprocal product: Plücker
coordinates move linearly under the turn) and ``(rb − ra) × wa`` are affine in ``(1, cos v,
sin v)`` too. A value where a pair becomes parallel, meets or coincides (within 10 times
:func:`~kinestat.serial.analytic.geometry.classify`'s tolerance) that does not at every value
is special: the geometry class or the elimination may change there, and it takes the path of
any new chain (fold, classify, formulation search). At every other value the class's tests
(pairs meeting or parallel, three consecutive axes through one point) answer as at the value
the formulation was found at (three consecutive axes across j that all meet or are parallel
pairwise at every value: no such fast path), and the formulation found there is kept: its
failures (Q of RR eq. 9 rank deficient for every pose, a singular pencil for every pose) are
polynomial identities in ``(cos v, sin v)`` that do not hold at that value, so hold at no more
than finitely many; a pose the kernel flags (deficient, ill-conditioned) takes the full path.
"""

from __future__ import annotations

import math
import sys
import threading

import numpy as np

from kinestat.serial.analytic import general6r
from kinestat.serial.analytic._common import _ENTRY, call_compiled
from kinestat.serial.analytic.geometry import PRESET, HomeAxes, home_axes, meet, parallel

__all__ = ["GeneralLock"]

_ANGLES = (0.0, 0.5 * math.pi, math.pi)
_TOL = 1e-9  # classify's tolerance
_TOL_SPECIAL = 1e-8  # a relation within this at a value (10 times classify's): special
_EXACT = 1e-12  # terms this small (rounding): a relation at every value
_CHECK_VALUES = (-2.3, -0.9, 0.6, 2.2)  # where an adopted formulation is checked too (any)
_CHECK_SEEDS = (1, 2)  # two draws of 24 random configurations it must find at each of them
_AFFINE = (0, 1, 2, 3, 5)  # the kernel arrays affine in (1, cos v, sin v): C, consts, links, LH, L


def _terms(x0: np.ndarray, x90: np.ndarray, x180: np.ndarray) -> np.ndarray:
    """``(3, ...)``: ``a, b, c`` with ``x(v) = a + b cos v + c sin v`` from x at 0, π/2, π."""
    a = 0.5 * (x0 + x180)
    return np.stack([a, 0.5 * (x0 - x180), x90 - a])


def _pair(ax: HomeAxes, a: int, b: int) -> np.ndarray:
    """``(7,)``: ``n = wa × wb``, ``(rb − ra) · n``, ``(rb − ra) × wa``."""
    n = np.cross(ax.w[a], ax.w[b])
    d = ax.r[b] - ax.r[a]
    return np.concatenate([n, [d @ n], np.cross(d, ax.w[a])])


def _kernels():
    from kinestat.serial.analytic import _locked_kernels as K  # lazy: Numba start-up

    return K


class GeneralLock:
    """Joint ``j`` (in between) of a 7R ``model``: ``fold(v)`` the chain folded at v. The
    relations of the axis pairs across the joint (:meth:`special`); once a value of the
    joint has been solved as a general 6R (:meth:`adopt`), the kernel's arrays at any value
    that is not special (:meth:`arrays`) and its single call (:meth:`bind`)."""

    def __init__(self, model, j: int, fold) -> None:
        self.j, self._fold = j, fold
        folds = [fold(v) for v in _ANGLES]
        axes = [home_axes(c) for c in folds]
        # classify's length scale at any value lies within these (|a| ± |(b, c)| of each
        # translation; only the folded one's depends on v)
        t = _terms(*[np.asarray(c.constants)[:, :3, 3] for c in folds])
        self.scale = max(1.0, float((np.abs(t[0]) + np.hypot(t[1], t[2])).max()))
        low = max(1.0, float((np.abs(t[0]) - np.hypot(t[1], t[2])).max()))
        pairs = [(a, b) for a in range(j) for b in range(j, 6)]
        R = _terms(*[np.array([_pair(ax, a, b) for a, b in pairs]) for ax in axes])
        self.R = np.ascontiguousarray(np.moveaxis(R, 0, -1))  # (pairs, 7, 3)
        size = np.abs(self.R).sum(axis=-1)  # bounds of |x(v)| over v
        par = size[:, :3].sum(axis=1) <= _EXACT
        coincide = par & (size[:, 4:].sum(axis=1) <= _EXACT * self.scale)
        meets = ~par & (size[:, 3] <= _EXACT * self.scale)
        self.mode = np.where(coincide, 3, np.where(par, 2, np.where(meets, 1, 0))).astype(np.int64)
        # a pair meeting at every value: classify's meeting test holds while |n| is above
        # this, and the value is special below it
        self.tol_dir = np.where(meets, np.maximum(_TOL_SPECIAL, size[:, 3] / (_TOL * low)),
                                _TOL_SPECIAL)
        self.tol_len = _TOL_SPECIAL * self.scale
        self.form = None  # the formulation (:meth:`adopt`), False where there is none
        self.P = self.tail = self.shapes = self.run = self._entry = None
        self._none = np.zeros((3, 0))
        self._basis = _no_basis()
        self._local = threading.local()  # per thread: the arrays of :meth:`new_value`
        # the terms describe the axes (checked at a fourth value), and no three consecutive
        # axes across j are related pairwise at every value
        related = {pair for pair, m in zip(pairs, self.mode, strict=True) if m}
        ax = axes[0]
        for a in range(6):
            for b in range(a + 1, 6):
                if (a < j) == (b < j) and (parallel(ax, a, b) or meet(ax, a, b) is not None):
                    related.add((a, b))
        self.usable = not any({(a, a + 1), (a + 1, a + 2), (a, a + 2)} <= related
                              for a in range(max(0, j - 2), min(j, 4)))
        x = np.array([_pair(home_axes(fold(1.0)), a, b) for a, b in pairs])
        c, s = math.cos(1.0), math.sin(1.0)
        if np.abs(R[0] + c * R[1] + s * R[2] - x).max() > 1e-9 * self.scale:
            self.usable = False

    def _eval(self, P: np.ndarray, v: float):
        """:func:`~kinestat.serial.analytic._locked_kernels.value_in` at one value: the
        arrays' flat values ``(1, m)`` and whether v is special."""
        out, special, values = np.empty((1, P.shape[1])), np.empty(1, dtype=bool), np.empty(1)
        values[0] = v
        entry = self._entry
        if entry is None:
            K = _kernels()
            call_compiled(K.value_in, P, self.R, self.mode, self.tol_dir, self.tol_len, values,
                          out, special)
            self._entry = _ENTRY.get((K.value_in, None))
        else:
            entry(P, self.R, self.mode, self.tol_dir, self.tol_len, values, out, special)
        return out, special[0]

    def special(self, v: float) -> bool:
        """Some axis pair across the joint is parallel, meets or coincides at ``v`` where it
        does not at every value (or the joint has no fast path)."""
        return not self.usable or self._eval(self._none, v)[1]

    def adopt(self, six, v: float, found=None) -> None:
        """The chain ``six`` folded at ``v`` (not special) is solved as a general 6R: its
        formulation (searched as for a new chain, or ``found`` by that search: ``(form,
        completeness)``) serves every value that is not special once it finds every one of 48
        random configurations (:data:`_CHECK_SEEDS`) at v and at :data:`_CHECK_VALUES` (a
        formulation that misses a few per cent of the poses passes the search's 24 at some
        values); else the first that does. The arrays' terms from the folds at 0, π/2, π,
        checked against ``six``'s own."""
        if self.form is not None or self.special(v):
            return
        form, frac = general6r.search(six) if found is None else found
        chains = [six] + [self._fold(w) for w in _CHECK_VALUES if not self.special(w)]

        def complete(f) -> bool:  # batches of 24: the serial kernel
            return all(general6r._raw_completeness(c, f, 24, seed) == 1.0 for c in chains
                       for seed in _CHECK_SEEDS)
        if frac < 1.0 or not complete(form):
            form = next((f for f in general6r.FORMULATIONS if f.shift in (0, 5) and
                         complete(f)), None)
        if form is None or form.shift not in (0, 5):
            self.form = False
            return
        folds = [general6r.model_arrays(self._fold(a), form) for a in _ANGLES]
        flat = [np.concatenate([np.ravel(arr[i]) for i in _AFFINE]) for arr in folds]
        P = np.ascontiguousarray(_terms(*flat))
        own = general6r.model_arrays(six, form)
        got, _ = self._eval(P, v)
        want = np.concatenate([np.ravel(own[i]) for i in _AFFINE])
        if np.abs(got[0] - want).max() > 1e-9 * max(1.0, float(np.abs(want).max())):
            self.form = False
            return
        ends = np.cumsum([0] + [own[i].size for i in _AFFINE]).tolist()
        self.shapes = [(ends[k], ends[k + 1], own[i].shape) for k, i in enumerate(_AFFINE)]
        self.tail = own[4], own[6], own[7], own[8]  # H3[0], offsets, order, sign
        self.P, self.form = P, form

    def arrays(self, v: float, special: bool = False) -> tuple | None:
        """The kernel's pose-independent arguments at ``v`` (as
        :func:`~kinestat.serial.analytic.general6r._compiled_data`'s, the basis found per
        pose), or None: no formulation yet, or a special value (unless ``special``)."""
        if self.P is None:
            return None
        out, at_special = self._eval(self.P, v)
        if at_special and not special:
            return None
        return self._views(out)

    def _views(self, out: np.ndarray) -> tuple:
        """The kernel's pose-independent arguments as views into the flat values ``out (1,
        m)`` of :meth:`_eval`, the basis found per pose."""
        f = out[0]
        C, consts, links, LH, L = [f[a:b].reshape(shape) for a, b, shape in self.shapes]
        C.flags.writeable = False  # as a chain's constants (the kernel's argument types)
        h0, off, order, sign = self.tail
        return (C, consts, links, LH, h0, L, off, order, sign) + self._basis

    def preset(self, six, v: float, args: tuple | None) -> None:
        """``six``, the chain folded at ``v`` for the full path (a batch of poses, a pose the
        single call leaves), takes its geometry class, formulation and arrays from the
        arrays ``args`` (:meth:`arrays`), or where ``v`` is special (``args`` None) the arrays
        for a formulation it then checks (a hint, :data:`~kinestat.serial.analytic.general6r.
        HINTS`) after its class is found."""
        if args is None:
            general6r.HINTS[six] = self.form
            general6r.PRESET[six] = (self.form, self.arrays(v, special=True)[:9], False)
            return
        PRESET[six] = ("general", {"axes": home_axes(six)})
        general6r.PRESET[six] = (self.form, args[:9], True)

    def new_value(self, T, tol: float, v: float):
        """The single call at a value ``v`` not yet seen, once :meth:`bind` has bound one
        (``self.run``): the kernel's arrays evaluated into this thread's buffers (no new
        arrays, no per-value objects), the basis found per pose. The result, None where the
        kernel flags the pose (the full path then), or False where ``v`` is special."""
        scratch = getattr(self._local, "arrays", None)
        if scratch is None:
            scratch = self._local.arrays = self._scratch()
        values, out, special, args = scratch
        values[0] = v
        self._entry(self.P, self.R, self.mode, self.tol_dir, self.tol_len, values, out, special)
        if special[0]:
            return False
        return self.run(T, tol, args, v)

    def _scratch(self) -> tuple:
        """One thread's ``(values (1,), out (1, m), special (1,), args)`` for
        :meth:`new_value`: ``args`` as :meth:`arrays`', views into ``out``."""
        out = np.empty((1, self.P.shape[1]))
        return np.empty(1), out, np.empty(1, dtype=bool), self._views(out)

    def bind(self, args: tuple, v: float, put, seen: bool = False):
        """The single call ``one(T (1, 4, 4) plain, tol)`` on ``args`` (:meth:`arrays`) with
        the joints put back by ``put = (entry, take, j)``, or None while the compiled entry
        points are not recorded. A value called again (``seen``: called once by
        :meth:`new_value`) gets the spurious subspace's basis (one SVD, about a call's time)
        in place of the kernel's search per pose."""
        run = self.run
        if run is None:
            cf = sys.modules.get("kinestat.serial.analytic._cf_kernels")
            check = None if cf is None else _ENTRY.get((cf.check_rigid, None))
            run = self.run = general6r.single_call(check, self.form, put)
            if run is None:
                return None
        calls = int(seen)

        def one(T, tol):
            nonlocal args, calls
            if calls == 1:
                from kinestat.serial.analytic._rr_deflate import model_basis  # lazy: Numba start-up

                args = args[:9] + model_basis(args[3])
            calls += 1
            return run(T, tol, args, v)
        return one


def _no_basis() -> tuple[np.ndarray, np.ndarray]:
    """:func:`~kinestat.serial.analytic._rr_deflate.no_basis` (found per pose)."""
    from kinestat.serial.analytic._rr_deflate import no_basis  # lazy: Numba start-up

    return no_basis()
