"""Shared by the platform studies: the platform from its TOML text, Table 3-1's working range,
poses displaced from home, and the per-pose measures (deflection, load, stiffness, singularity).

Vibhute 2011 Table 3-1 (design objective specifications of the prototype): individual connector
deflection 5 mm, maximum perpendicular load 50 N, motion range 4 mm in z, 3.5 mm in x and y,
6° about z, 4° about x and y. We read a motion range as ± about the home pose, and "perpendicular
load" as |F_z| of the external wrench holding the top (z perpendicular to the base plane).
A pose is *within spec* when every leg deflects at most the connector limit and |F_z| is at most
the load limit. Displacements are taken at the top platform's centre (its centroid at home):
``T = Trans(c + t) · Rot(r) · Trans(−c) · T_home`` with r the rotation vector (rx, ry, rz),
base-frame axes.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

import kinestat.hardware.platform_spec as spec
from kinestat.errors import InputError
from kinestat.io.library import embedded_text
from kinestat.io.platform_toml import loads_platform
from kinestat.io.textfile import read_text_file
from kinestat.parallel import leg_lengths, singularity_measure, spring_wrench, stiffness
from kinestat.parallel.legs import top_points_in_base

__all__ = ["TABLE_3_1", "platform_text", "load_platform", "platform_spec", "displaced_poses",
           "evaluate_poses", "axis_check", "range_box"]

#: Vibhute 2011 Table 3-1 (mm, N, degrees)
TABLE_3_1 = {"max_deflection": spec.MAX_DEFLECTION, "max_load": spec.MAX_LOAD,
             "range_mm": spec.MOTION_RANGE_MM, "range_deg": spec.MOTION_RANGE_DEG}

#: dimensionless |det j| below which a pose counts as singular (kinestat.parallel.singularity)
SINGULAR_TOL = 1e-9


def platform_text(path: str | None) -> tuple[str, str]:
    """(label, TOML text) of a platform file, or of the embedded 2011 prototype if None."""
    if path is None:
        return "prototype-2011", embedded_text("platforms", "prototype-2011.toml")

    return str(path), read_text_file(path, "platform file")


def load_platform(label: str, text: str):
    """The platform described by TOML ``text`` (``label`` names it in errors)."""

    return loads_platform(text, source=label)


def platform_spec(study: str, source: tuple[str, str], *, range_mm, range_deg,
                  chunk_size: int, arrays: bool, **entries) -> dict:
    """The spec entries every platform study has — ``study``, ``platform`` and
    ``platform_text`` (``source``: :func:`platform_text`), the motion range, ``chunk_size``,
    ``arrays`` — plus ``entries``."""
    label, text = source
    range_box(range_mm, range_deg)  # finite, non-negative: refused before anything runs
    for key in ("max_deflection", "max_load"):
        v = entries.get(key)
        if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise InputError(f"--{key.replace('_', '-')} must be a finite number > 0, got {v}")
    return {"study": study, "platform": label, "platform_text": text,
            "range_mm": [float(x) for x in range_mm], "range_deg": [float(x) for x in range_deg],
            "chunk_size": int(chunk_size), "arrays": bool(arrays), **entries}


def range_box(range_mm, range_deg) -> np.ndarray:
    """Half-widths ``(6,)`` of the motion range: x, y, z (length unit), rx, ry, rz (radians)."""
    r = np.concatenate([np.asarray(range_mm, float), np.radians(np.asarray(range_deg, float))])
    if r.shape != (6,) or not np.all(np.isfinite(r)) or np.any(r < 0):
        raise InputError(f"motion ranges must be 3 + 3 non-negative numbers, got {r.tolist()}")
    return r


def _rotvec(r: np.ndarray) -> np.ndarray:

    return Rotation.from_rotvec(r.reshape(-1, 3)).as_matrix().reshape(r.shape[:-1] + (3, 3))


def displaced_poses(platform, d: np.ndarray) -> np.ndarray:
    """Poses ``(..., 4, 4)`` displaced from home by ``d (..., 6)`` = (x, y, z, rx, ry, rz)
    at the top's centre (see the module docstring)."""

    H = platform.home_pose
    c = top_points_in_base(platform, H).mean(axis=0)
    R = _rotvec(d[..., 3:])
    T = np.zeros(d.shape[:-1] + (4, 4))
    T[..., :3, :3] = R @ H[:3, :3]
    T[..., :3, 3] = c + d[..., :3] + np.einsum("...ij,j->...i", R, H[:3, 3] - c)
    T[..., 3, 3] = 1.0
    return T


def evaluate_poses(platform, T: np.ndarray, max_deflection: float, max_load: float) -> dict:
    """Per-pose measures ``(...)`` of the platform at poses ``T``.

    ``max_deflection`` max |l − l0| over the legs; ``max_leg_force`` max |k (l − l0)|;
    ``force_z`` |F_z| of the spring wrench (the external load holding the top there);
    ``singularity`` the dimensionless |det j|; ``k_eig_min/max`` and ``k_cond`` the extreme
    eigenvalues and their ratio of the symmetric part of ``D K D`` (K Vibhute eq. 2-17, ray
    order; D = diag(1, 1, 1, 1/s, 1/s, 1/s), s = platform.scale, so every entry is force per
    length); ``ok`` within both limits and not singular.
    """

    defl = np.abs(leg_lengths(platform, T) - platform.free_lengths)
    w = spring_wrench(platform, T)
    sing = singularity_measure(platform, T)
    K = stiffness(platform, T)
    s = np.r_[1.0, 1.0, 1.0, [1.0 / platform.scale] * 3]
    Kn = K * s[:, None] * s[None, :]
    e = np.linalg.eigvalsh(0.5 * (Kn + np.swapaxes(Kn, -1, -2)))
    ae = np.abs(e)
    out = {"max_deflection": defl.max(axis=-1),
           "max_leg_force": (platform.stiffness * defl).max(axis=-1),
           "force_z": np.abs(w[..., 2]), "singularity": sing,
           "k_eig_min": e[..., 0], "k_eig_max": e[..., -1],
           "k_cond": ae.max(axis=-1) / np.maximum(ae.min(axis=-1), 1e-300)}
    out["within_deflection"] = out["max_deflection"] <= max_deflection
    out["within_load"] = out["force_z"] <= max_load
    out["ok"] = out["within_deflection"] & out["within_load"] & (sing > SINGULAR_TOL)
    return out


def axis_check(platform, box: np.ndarray, max_deflection: float, max_load: float,
               points: int = 4) -> dict:
    """Table 3-1 axis by axis: each of the six motions alone, from home to ± its range
    (``points`` steps each way). ``meets`` if every such pose is within spec."""
    steps = np.arange(1, points + 1) / points
    d = np.zeros((6, 2, points, 6))
    for a in range(6):
        d[a, 0, :, a] = steps * box[a]
        d[a, 1, :, a] = -steps * box[a]
    r = evaluate_poses(platform, displaced_poses(platform, d), max_deflection, max_load)
    per_axis = r["ok"].all(axis=(1, 2))
    return {"meets": bool(per_axis.all()),
            "axes_ok": dict(zip(("x", "y", "z", "rx", "ry", "rz"),
                                (bool(x) for x in per_axis), strict=True)),
            "max_deflection": float(r["max_deflection"].max()),
            "max_force_z": float(r["force_z"].max()),
            "min_singularity": float(r["singularity"].min())}


def as_deg(d: np.ndarray) -> np.ndarray:
    """Displacements with the rotations in degrees (for the rows on disk)."""
    out = d.copy()
    out[..., 3:] *= 180.0 / math.pi
    return out
