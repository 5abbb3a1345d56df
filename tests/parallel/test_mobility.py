"""Grübler–Kutzbach mobility (kinestat.parallel.mobility): textbook mechanisms' known
mobilities, and the platform's count against its instantaneous mobility computed from the
joints' screws at the actual geometry (the null space of the assembly's velocity constraints)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.linalg import null_space

from kinestat.cli.main import main
from kinestat.parallel.legs import as_pose
from kinestat.parallel.mobility import gruebler_kutzbach, platform_mobility, platform_structure
from kinestat.parallel.platform import Platform, special_6_6

# (mechanism, space λ, links n incl. the fixed one, joints, mobility from the textbooks:
# Tsai, Robot Analysis, 1999, ch. 1; Norton, Design of Machinery, ch. 2)
TEXTBOOK = [
    ("planar four-bar", 3, 4, "RRRR", 1),
    ("slider-crank", 3, 4, "RRRP", 1),
    ("planar five-bar", 3, 5, "RRRRR", 2),
    ("Watt six-bar", 3, 6, "RRRRRRR", 1),
    ("three-bar truss", 3, 3, "RRR", 0),
    ("spatial RSSR (one idle spin of the coupler)", 6, 4, "RSSR", 2),
    ("six-axis serial arm", 6, 7, "RRRRRR", 6),
    ("Stewart-Gough 6-UPS", 6, 14, "UPS" * 6, 6),
    ("6-SPS (six idle leg spins)", 6, 14, "SPS" * 6, 12),
    ("3-RPR planar parallel", 3, 8, "RPR" * 3, 3),
]


@pytest.mark.parametrize("name, space, links, joints, expected", TEXTBOOK,
                         ids=[t[0] for t in TEXTBOOK])
def test_textbook_mobilities(name, space, links, joints, expected):
    assert gruebler_kutzbach(links, joints, space=space) == expected
    # by freedoms as well as by joint type
    from kinestat.parallel.mobility import JOINT_FREEDOMS
    assert gruebler_kutzbach(links, [JOINT_FREEDOMS[j] for j in joints], space) == expected


def test_the_count_misses_an_overconstrained_linkage():
    # Bennett's spatial 4R moves with one freedom; the count says -2 (dependent constraints):
    # the criterion's stated limit, kept visible
    assert gruebler_kutzbach(4, "RRRR") == -2


def _screw_rev(u, p):
    u = np.asarray(u, float) / np.linalg.norm(u)
    return np.concatenate([u, np.cross(p, u)])


def _joint_screws(kind: str, point, axis):
    """Unit screws (ω; v at the origin) a joint permits: S at ``point``, U at ``point`` about
    two axes across ``axis``, P along ``axis``."""
    if kind == "P":
        return [np.concatenate([np.zeros(3), axis / np.linalg.norm(axis)])]
    if kind == "S":
        return [_screw_rev(e, point) for e in np.eye(3)]
    a = axis / np.linalg.norm(axis)
    e1 = np.cross(a, [1.0, 0.3, 0.1])
    e1 /= np.linalg.norm(e1)
    return [_screw_rev(e1, point), _screw_rev(np.cross(a, e1), point)]


def instantaneous_mobility(platform, pose, chain: str) -> int:
    """Dimension of the assembly's velocity space: bodies top (0) and each leg's cylinder and
    piston (1 + 2i, 2 + 2i), six twist components each (the base is fixed); every joint
    requires the relative twist of the bodies it joins to lie in the span of its screws."""
    T = as_pose(pose, "pose")
    top = (T[:3, :3] @ platform.top_points.T).T + T[:3, 3]
    nb = 13
    rows = []

    def constrain(a, b, screws):  # twist_b − twist_a ∈ span(screws); a, b: body or None (base)
        S = np.column_stack(screws)
        C = null_space(S.T)  # the complement: C^T (t_b − t_a) = 0
        for c in C.T:
            row = np.zeros(6 * nb)
            if b is not None:
                row[6 * b:6 * b + 6] += c
            if a is not None:
                row[6 * a:6 * a + 6] -= c
            rows.append(row)

    for i in range(6):
        b_pt, t_pt = platform.base_points[i], top[i]
        axis = t_pt - b_pt
        cyl, pis = 1 + 2 * i, 2 + 2 * i
        constrain(None, cyl, _joint_screws(chain[0], b_pt, axis))
        constrain(cyl, pis, _joint_screws("P", b_pt, axis))
        constrain(pis, 0, _joint_screws(chain[2], t_pt, axis))
    A = np.array(rows)
    return 6 * nb - int(np.linalg.matrix_rank(A, tol=1e-9 * np.max(np.abs(A))))


def _octahedral_33() -> Platform:
    """A 3-3 platform: base triangle O, P, Q and top triangle R, S, T, legs O-R, O-S, P-S, P-T,
    Q-T, Q-R (kinestat.parallel.fk33's order)."""
    ang = np.radians([90.0, 210.0, 330.0])
    base3 = np.column_stack([100 * np.cos(ang), 100 * np.sin(ang), np.zeros(3)])
    top3 = np.column_stack([50 * np.cos(ang + np.pi / 3), 50 * np.sin(ang + np.pi / 3),
                            np.zeros(3)])
    base = base3[[0, 0, 1, 1, 2, 2]]
    topp = top3[[2, 0, 0, 1, 1, 2]]
    home = np.eye(4)
    home[2, 3] = 80.0
    lengths = np.linalg.norm(topp + [0, 0, 80.0] - base, axis=1)
    return Platform(base, topp, np.full(6, 2.0), lengths, home, name="octahedral 3-3")


@pytest.mark.parametrize("chain, expected", [("UPS", 6), ("SPS", 12)])
@pytest.mark.parametrize("kind", ["special 6-6", "3-3"])
def test_the_platforms_count_is_its_instantaneous_mobility(kind, chain, expected):
    plat = special_6_6() if kind == "special 6-6" else _octahedral_33()
    mob = platform_mobility(plat)
    assert mob["structure"] == kind
    assert mob["chains"][chain]["mobility"] == expected
    assert instantaneous_mobility(plat, plat.home_pose, chain) == expected
    # away from home too (a turned, shifted top: the count holds off singular poses)
    T = plat.home_pose.copy()
    c, s = np.cos(0.05), np.sin(0.05)
    T[:3, :3] = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]]) @ T[:3, :3]
    T[:3, 3] += [1.0, -0.5, 0.7]
    assert instantaneous_mobility(plat, T, chain) == expected
    top = mob["chains"][chain]["top"]
    assert top == 6 and mob["chains"][chain]["idle"] == expected - 6


def test_a_general_layout_is_named_so():
    rng = np.random.default_rng(3)
    p = special_6_6()
    q = Platform(p.base_points + rng.normal(0, 3.0, (6, 3)), p.top_points, p.stiffness,
                 p.free_lengths, p.home_pose)
    assert platform_structure(q) == "general 6-6"
    assert platform_mobility(q)["mobility"] == 6


def test_platform_info_shows_the_mobility(capsys):
    assert main(["platform", "info", "--json"]) == 0
    mob = json.loads(capsys.readouterr().out)["mobility"]
    assert mob["mobility"] == 6 and mob["chain"] == "UPS" and mob["structure"] == "special 6-6"
    assert mob["chains"]["SPS"]["mobility"] == 12 and mob["chains"]["SPS"]["idle"] == 6
    assert main(["platform", "info"]) == 0
    out = capsys.readouterr().out
    assert "mobility" in out and "UPS legs M = 6" in out and "SPS legs M = 12" in out
