"""Test arms for the all-solutions IK, built through the public ChainModel constructors, and an
independent oracle: many-start damped Newton with de-duplication."""

from __future__ import annotations

import math

import numpy as np

import kinestat
from kinestat.mechanism.chain import from_standard_dh

PI = math.pi


def ur5():
    """UR5 (DH: d1=0.089159, a2=-0.425, a3=-0.39225, d4=0.10915, d5=0.09465, d6=0.0823)."""
    rows = np.column_stack([np.zeros(6), [0.089159, 0, 0, 0.10915, 0.09465, 0.0823],
                            [0, -0.425, -0.39225, 0, 0, 0], [PI / 2, 0, 0, PI / 2, -PI / 2, 0]])
    return from_standard_dh(rows, name="ur5", length_unit="m")


def jaco6():
    """Kinova Jaco2 6-DOF type: a non-spherical 60° wrist (Kinova's published classic DH)."""
    aa = PI / 6
    k = math.sin(aa) / math.sin(2 * aa)
    D1, D2, D3, D4, D5, D6, e2 = 0.2755, 0.41, 0.2073, 0.0741, 0.0741, 0.16, 0.0098
    rows = [[0, D1, 0, PI / 2], [-PI / 2, 0, D2, PI], [PI / 2, -e2, 0, PI / 2],
            [0, -(D3 + k * D4), 0, 2 * aa], [PI, -(k * D4 + k * D5), 0, 2 * aa],
            [-PI / 2, -(k * D5 + D6), 0, PI]]
    return from_standard_dh(rows, name="jaco6", length_unit="m")


def random_6r(seed: int):
    """A random general 6R chain (standard DH, lengths in [-1, 1] m, angles uniform)."""
    rng = np.random.default_rng(seed)
    rows = np.column_stack([rng.uniform(-PI, PI, 6), rng.uniform(-1, 1, 6),
                            rng.uniform(-1, 1, 6), rng.uniform(-PI, PI, 6)])
    return from_standard_dh(rows, name=f"random6r-{seed}", length_unit="m")


def middle_arm(seed: int, first: int = 2):
    """A random standard-DH 6R (angles in [-π, π], lengths in [-1, 1] m) whose axes first,
    first + 1, first + 2 (1-based) meet: a = 0 between them and no offset along the middle."""
    rng = np.random.default_rng(seed)
    rows = np.column_stack([rng.uniform(-PI, PI, 6), rng.uniform(-1, 1, 6),
                            rng.uniform(-1, 1, 6), rng.uniform(-PI, PI, 6)])
    i = first - 1  # row of the first joint of the triple (0-based)
    rows[i, 2] = rows[i + 1, 2] = rows[i + 1, 1] = 0.0
    return from_standard_dh(rows, ["revolute"] * 6, name=f"middle{first}-{seed}",
                            length_unit="m")


def arm(name: str):
    if name.startswith("middle"):  # "middle2-1": axes 2-4 meeting, seed 1
        first, seed = name[6:].split("-")
        return middle_arm(int(seed), int(first))
    if name == "ur5":
        return ur5()
    if name == "jaco6":
        return jaco6()
    if name.startswith("random"):
        return random_6r(int(name[6:]))
    if name in INDUSTRIAL:
        return industrial(name)
    return kinestat.load(name)


def wrapped_distance(a: np.ndarray, b: np.ndarray, rotates=True) -> np.ndarray:
    """Max over joints of the difference, 2π-wrapped where ``rotates`` (default: all joints)."""
    d = a - b
    return np.max(np.abs(np.where(rotates, np.mod(d + PI, 2 * PI) - PI, d)), axis=-1)


def slot_residuals(model, res, T: np.ndarray):
    """Residuals of every valid slot of the all-solutions result ``res`` against its poses
    ``T (..., 4, 4)``, recomputed here with :func:`kinestat.fk` (independent of the solver):
    ``(pos, dR)`` of shape ``(..., K)``, the flange-origin distance and the Frobenius norm of
    the rotation difference, 0 in slots that are not valid."""
    F = kinestat.fk(model, np.where(res.valid[..., None], res.q, 0.0))
    pos = np.linalg.norm(F[..., :3, 3] - T[..., None, :3, 3], axis=-1)
    dR = np.linalg.norm(F[..., :3, :3] - T[..., None, :3, :3], axis=(-2, -1))
    return np.where(res.valid, pos, 0.0), np.where(res.valid, dR, 0.0)


def _twist_error(F, T):
    dR = T[..., :3, :3] @ np.swapaxes(F[..., :3, :3], -1, -2)
    ang = 0.5 * np.stack([dR[..., 2, 1] - dR[..., 1, 2], dR[..., 0, 2] - dR[..., 2, 0],
                          dR[..., 1, 0] - dR[..., 0, 1]], -1)
    p = F[..., :3, 3]
    return np.concatenate([ang, T[..., :3, 3] - p - np.cross(ang, p)], -1)


def newton_solutions(model, T: np.ndarray, starts: int = 400, iters: int = 60,
                     seed: int = 0, span: float = 2.0) -> list[np.ndarray]:
    """Distinct IK solutions of each pose ``T (P, 4, 4)`` by damped Newton from many random
    starts (Levenberg–Marquardt on the twist error), de-duplicated modulo 2π (revolute joints;
    prismatic joints start uniformly in ``[−span, span]`` and are not wrapped)."""
    rng = np.random.default_rng(seed)
    P = T.shape[0]
    rot = ~model.prismatic
    q = rng.uniform(-PI, PI, (P, starts, 6))
    q = np.where(rot, q, q / PI * span)
    Tt = np.broadcast_to(T[:, None], (P, starts, 4, 4))
    lam = np.full((P, starts), 1e-2)
    e = _twist_error(kinestat.fk(model, q), Tt)
    en = np.linalg.norm(e, axis=-1)
    for _ in range(iters):
        J = kinestat.jacobian(model, q)
        JT = np.swapaxes(J, -1, -2)
        A = JT @ J + lam[..., None, None] * np.eye(6)
        dq = np.linalg.solve(A, (JT @ e[..., None]))[..., 0]
        qn = q + dq
        en_new = _twist_error(kinestat.fk(model, qn), Tt)
        nn = np.linalg.norm(en_new, axis=-1)
        better = nn < en
        q = np.where(better[..., None], qn, q)
        e = np.where(better[..., None], en_new, e)
        en = np.where(better, nn, en)
        lam = np.where(better, np.maximum(lam / 10, 1e-12), lam * 10)
    out = []
    for i in range(P):
        sols: list[np.ndarray] = []
        for qi in q[i][en[i] < 1e-11]:
            qi = np.where(rot, np.mod(qi + PI, 2 * PI) - PI, qi)
            if all(wrapped_distance(qi, s, rot) > 1e-6 for s in sols):
                sols.append(qi)
        out.append(np.array(sols).reshape(-1, 6))
    return out


def random_pieper(seed: int, parallel: str = ""):
    """A random spherical-wrist 6R (standard DH with a4 = a5 = d5 = 0: axes 4, 5, 6 meet) whose
    shoulder is offset (axes 1, 2 skew); ``parallel="12"`` or ``"23"`` makes those two axes
    parallel (α = 0)."""
    rng = np.random.default_rng(seed)
    rows = np.column_stack([rng.uniform(-PI, PI, 6), rng.uniform(-1, 1, 6),
                            rng.uniform(-1, 1, 6), rng.uniform(-PI, PI, 6)])
    rows[3, 2] = rows[4, 2] = rows[4, 1] = 0.0
    if parallel:
        rows[int(parallel[0]) - 1, 3] = 0.0
    return from_standard_dh(rows, name=f"pieper{parallel}-{seed}", length_unit="m")


#: industrial arms with an offset shoulder and a spherical wrist: rtb-data's URDF (path under
#: its ``xacro/`` folder, tip link) or a Robotics Toolbox DH model (class name)
INDUSTRIAL = {
    "kr16": ("kuka_description/kuka_kr16/urdf/kr16_2.urdf", None),
    "kr120": ("kuka_description/kuka_kr120/urdf/kr120r2500pro.urdf", None),
    "kr210": ("kuka_description/kuka_kr210/urdf/kr210l150.urdf", "tool0"),
    "kr5": ("rtb:KR5", None),
    "irb140": ("rtb:IRB140", None),
}


def industrial(name: str):
    """An arm of :data:`INDUSTRIAL` (the test skips when its package is not installed)."""
    import pytest

    src, tip = INDUSTRIAL[name]
    if src.startswith("rtb:"):
        rtb = pytest.importorskip("roboticstoolbox")
        robot = getattr(rtb.models.DH, src[4:])()
        rows = [[L.offset, L.d, L.a, L.alpha] for L in robot.links]
        return from_standard_dh(np.array(rows), name=name, length_unit="m")
    from pathlib import Path

    rtbdata = pytest.importorskip("rtbdata", reason="rtb-data is not installed "
                                  "(pip install -r requirements/dev.txt)")
    return kinestat.load(Path(rtbdata.__file__).parent / "xacro" / src, tip=tip)


def random_shoulder(seed: int):
    """A random 6R whose first three axes meet (standard DH with a1 = a2 = d2 = 0) and whose
    wrist is not spherical."""
    rng = np.random.default_rng(seed)
    rows = np.column_stack([rng.uniform(-PI, PI, 6), rng.uniform(-1, 1, 6),
                            rng.uniform(-1, 1, 6), rng.uniform(-PI, PI, 6)])
    rows[0, 2] = rows[1, 2] = rows[1, 1] = 0.0
    return from_standard_dh(rows, name=f"shoulder-{seed}", length_unit="m")
