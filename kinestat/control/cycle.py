"""Per-cycle data: what a cycle's decision computes from its measurement, computed once.

In the spirit of Pinocchio's Model/Data split: the :class:`~kinestat.control.model.ControlModel`
is immutable and knows nothing of the cycle; :class:`CycleData` holds the values the decision
needs more than once at the measured pose — the platform's loaded stiffness ``K`` (axis order
``[δφ; δx_O]``, Vibhute eq. 2-17), the tool tip in the base and fixed frames, the tip's
translational compliance ``C_tip`` (eq. 2-16/2-17) and the leg directions — each computed on
first use by the same functions the callers used before (so the values are the same, bit for
bit), except K and C_tip: compiled for the one pose
(:func:`kinestat.parallel.stiffness.stiffness_axis_trusted`,
:func:`~kinestat.parallel.stiffness.tip_compliance_one`), equal to the NumPy formulations to
rounding. :func:`cycle_data` finds a measurement's data (kept with the measurement, so
that :func:`~kinestat.control.controller.decide`, the envelope's prediction and the follow
task's control law share it without passing it around, and it goes with the measurement).

Small helpers of the cycle's hot path, each the value of the NumPy call it stands for without its
per-call set-up (a 3-vector costs ~1 µs per NumPy call, most of it set-up): :func:`cross3`,
:func:`cross_rows`, :func:`norm3` (``numpy.linalg.norm`` of one 3-vector), :func:`replace`
(``dataclasses.replace`` of a plain frozen dataclass: the follow task's state is replaced
several times a cycle) and :func:`mount_inverse` (the model's constant ``inv(mount)``, made
once per model).
"""

from __future__ import annotations

import dataclasses
import math
import weakref

import numpy as np

from kinestat.control.model import ControlModel
from kinestat.control.wrench import Measurement
from kinestat.parallel.legs import leg_directions_trusted
from kinestat.parallel.stiffness import stiffness_axis_trusted, tip_compliance_one
from kinestat.spatial.transforms import apply_one, cross3, inv

__all__ = ["CycleData", "cycle_data", "cross3", "cross_rows", "norm3", "replace",
           "mount_inverse"]


def cross_rows(a, b) -> np.ndarray:
    """Row-wise ``a × b`` of two (n, 3) arrays: :func:`numpy.cross`'s products and
    differences, the same values, without its broadcasting set-up."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    out = np.empty(a.shape)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def norm3(v) -> float:
    """``|v|`` of one 3-vector: the square root of ``v0² + v1² + v2²`` summed in order, as
    :func:`numpy.linalg.norm` sums it (equal to it to rounding; bit for bit where its dot
    product sums in order, as on the reference machine), without its set-up.

    >>> norm3(np.array([3.0, 4.0, 12.0]))
    13.0
    """
    a, b, c = np.asarray(v, dtype=float).tolist()
    return math.sqrt(a * a + b * b + c * c)


_PLAIN: dict[type, frozenset | None] = {}


def _plain_fields(cls: type) -> frozenset | None:
    """The field names of a dataclass whose ``__init__`` only stores its fields (no
    ``__post_init__``, every field an ``__init__`` argument, no ``InitVar``); None otherwise."""
    if not dataclasses.is_dataclass(cls) or hasattr(cls, "__post_init__") \
            or not cls.__dataclass_params__.init or hasattr(cls, "__slots__"):
        return None
    fields = dataclasses.fields(cls)
    if len(fields) != len(cls.__dataclass_fields__) or not all(f.init for f in fields):
        return None
    return frozenset(f.name for f in fields)


def replace(obj, /, **changes):
    """:func:`dataclasses.replace`: a copy of the dataclass instance ``obj`` with ``changes``.
    For a dataclass whose ``__init__`` only stores its fields (:func:`_plain_fields`) the copy
    is made by copying the instance's fields (the same object ``replace`` builds through
    ``__init__``, ~5× faster); any other class, unknown names or an instance that carries
    more than its fields (a cache) go through :func:`dataclasses.replace`.
    """
    cls = type(obj)
    names = _PLAIN.get(cls, False)
    if names is False:
        names = _PLAIN[cls] = _plain_fields(cls)
    d = getattr(obj, "__dict__", None)
    if names is None or d is None or len(d) != len(names) or not changes.keys() <= names:
        return dataclasses.replace(obj, **changes)
    new = object.__new__(cls)
    fields = d.copy()
    fields.update(changes)
    object.__setattr__(new, "__dict__", fields)
    return new


_MOUNT_INV: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def mount_inverse(model: ControlModel) -> np.ndarray:
    """``inv(model.mount)`` (4, 4), read-only, made once per model (the mount is constant)."""
    got = _MOUNT_INV.get(model)
    if got is None:
        got = _MOUNT_INV[model] = inv(model.mount)
        got.setflags(write=False)
    return got


class _once:
    """A per-instance value computed on first use and stored in the instance (as
    :class:`functools.cached_property`, without its lock: a cycle's data belongs to one
    decision)."""

    def __init__(self, fn) -> None:
        self.fn = fn
        self.name = fn.__name__
        self.__doc__ = fn.__doc__

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        value = obj.__dict__[self.name] = self.fn(obj)
        return value


class CycleData:
    """Values of one measurement at the model's platform, each computed on first use.

    Attributes:
        K: (6, 6) the platform stiffness at the measured top pose, axis order.
        tip_base: (3,) the tool tip in the platform base frame (the measured, deflected tip).
        tip_fixed: (3,) the same in the fixed frame (:meth:`Measurement.tip`).
        C_tip: (3, 3) the tip's translational compliance, base frame (mm/N).
        leg_directions: ((6, 3), (6,)) unit leg directions and leg lengths at the top pose.
    """

    def __init__(self, model: ControlModel, meas: Measurement) -> None:
        self.model = model
        self.meas = meas
        # the platform's forward kinematics made this pose (checked there): used unchecked
        self.top_pose = np.asarray(meas.top_pose, dtype=float)

    @_once
    def K(self) -> np.ndarray:
        return stiffness_axis_trusted(self.model.platform, self.top_pose)

    @_once
    def tip_base(self) -> np.ndarray:
        return apply_one(self.top_pose, self.model.tool_tip_top)

    @_once
    def tip_fixed(self) -> np.ndarray:
        return self.meas.tip(self.model)

    @_once
    def C_tip(self) -> np.ndarray:
        return tip_compliance_one(self.K, self.tip_base)

    @_once
    def leg_directions(self) -> tuple[np.ndarray, np.ndarray]:
        return leg_directions_trusted(self.model.platform, self.top_pose)


def cycle_data(model: ControlModel, meas: Measurement) -> CycleData:
    """The :class:`CycleData` of ``meas`` at ``model``, made on first use (and again for
    another model). Kept in the measurement's instance dictionary beside
    :meth:`Measurement.tip`'s cache (a cache, not a field: the measurement stays frozen, and
    the data goes with it)."""
    d = meas.__dict__.get("_cycle_data")
    if d is None or d.model is not model or d.meas is not meas:
        d = meas.__dict__["_cycle_data"] = CycleData(model, meas)
    return d
