"""Per-model data of the compiled kernels, kept OUTSIDE the immutable model.

In the spirit of Pinocchio's Model/Data split: :class:`~kinestat.mechanism.chain.ChainModel`
holds only the mechanism; the contiguous arrays the Numba kernels take (constants, joint kind
codes, pitches, the packed vector of the single-configuration entry points, limits and the
model's characteristic length) are built once per model on first use and dropped when the model
is garbage collected. The cache is keyed by ``id(model)`` (a plain dict lookup, ~30 ns, which
the ~1 µs single-configuration FK fast path can afford); a ``weakref.finalize`` removes the
entry before the id can be reused.
"""

from __future__ import annotations

import weakref

import numpy as np

from kinestat.mechanism.chain import ChainModel

__all__ = ["KernelData", "kernel_data"]


def _ro(a) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=float).copy()
    a.setflags(write=False)
    return a


class KernelData:
    """The kernel arguments of one model (read-only arrays).

    Attributes:
        n: number of joints.
        constants: ``(n+1, 4, 4)`` C-contiguous.
        kinds: ``(n,)`` int64 :class:`~kinestat.mechanism.joints.JointKind` codes.
        pitches: ``(n,)``.
        packed: n, the constants, the kinds (as floats) and the pitches in one vector.
        address: where ``packed``'s data are, as a float (exact: addresses are below
            2**53; a float reaches a compiled function faster than a large int); what
            ``fk_one`` and ``jacobian_one`` take.
        lower, upper: joint limits ``(n,)``.
        jshape: ``(6, n)``, the shape of one Jacobian.
        scale: :func:`~kinestat.serial.lengths.characteristic_length` of the model (no q),
            filled in by :mod:`kinestat.serial.ik` on first use.
    """

    __slots__ = ("n", "constants", "kinds", "pitches", "packed", "address", "lower", "upper",
                 "scale", "jshape")

    def __init__(self, model: ChainModel) -> None:
        self.n = model.n
        self.constants = _ro(model.constants)
        kinds = np.ascontiguousarray(model.kind_codes, dtype=np.int64).copy()
        kinds.setflags(write=False)
        self.kinds = kinds
        self.pitches = _ro(model.pitches)
        self.packed = _ro(np.concatenate([[float(model.n)], self.constants.ravel(),
                                          kinds.astype(float), self.pitches]))
        self.address = float(self.packed.ctypes.data)
        self.lower = _ro(model.lower)
        self.upper = _ro(model.upper)
        self.scale: float | None = None  # set by kinestat.serial.ik on first use
        self.jshape = (6, model.n)

    @property
    def args(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(constants, kinds, pitches)``, the leading arguments of the batch kernels."""
        return self.constants, self.kinds, self.pitches


_BY_ID: dict[int, KernelData] = {}


def kernel_data(model: ChainModel) -> KernelData:
    """The :class:`KernelData` of ``model``, built on first use.

    >>> from kinestat.mechanism.chain import from_standard_dh
    >>> m = from_standard_dh([[0.0, 0.0, 1.0, 0.0]])
    >>> d = kernel_data(m)
    >>> d.n, d.packed.shape, kernel_data(m) is d
    (1, (35,), True)
    """
    d = _BY_ID.get(id(model))
    if d is None:
        d = _BY_ID[id(model)] = KernelData(model)
        weakref.finalize(model, _BY_ID.pop, id(model), None)
    return d
