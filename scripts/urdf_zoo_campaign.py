"""URDF zoo campaign: kinestat's URDF import on robots and files it was not developed on.

Run ``.venv/bin/python scripts/urdf_zoo_campaign.py [--quick] [--json OUT] [--only TEXT]``.

The zoo: every chain (root link to each leaf link) of every URDF file of example-robot-data and
of rtb-data (its ``.urdf`` files and its xacro files, expanded by the ``xacro`` package), and
synthetic variants of a few real 6- and 7-joint arms (:mod:`urdf_zoo_variants`: fixed joints
between moving ones, a world joint, a rotated tool frame, reframed and negated axes, rpy at
gimbal lock, continuous joints, limits wider than a turn, numbers in scientific notation,
comments/CDATA/namespaces, two-finger grippers, missing mesh files, a default XML namespace).

Per chain, every check is against an independent computation:

- loading: a chain through a floating/planar joint or a moving ``<mimic>`` joint must be one
  KinestatError; any other chain must load; nothing else may escape;
- FK and the space Jacobian at random configurations against Pinocchio's model of the same
  text (``buildModelFromXML``; joints matched by name);
- 6 joints: every valid ``ik_all`` solution reproduces the pose by Pinocchio's FK (≤ 1e-9),
  the generating configuration is among them, and the number of distinct solutions equals
  EAIK's (HPRobot) and ik-geo's verified ones where those apply; 7 joints: the same with one
  joint locked (EAIK ``fixed_axes``);
- numerical ``kinestat.ik``: success on reachable poses, every success verified by Pinocchio,
  no success on a pose out of reach.

Prints one line per failing chain and a summary per check; exit status 1 if anything failed.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

_ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(_ROOT / "benchmarks"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(_ROOT))  # this checkout's kinestat

import kinestat  # noqa: E402
from kinestat.errors import KinestatError  # noqa: E402
from kinestat.io.urdf import from_urdf  # noqa: E402

PI = math.pi
FK_TOL = 1e-9
IK_TOL = 1e-9


# -- the zoo --------------------------------------------------------------------------------
def _site(pkg: str) -> Path | None:
    from importlib.metadata import PackageNotFoundError, distribution

    try:
        d = distribution(pkg)
    except PackageNotFoundError:
        return None
    return Path(str(d.locate_file("")))


def real_files() -> list[tuple[str, str]]:
    """(name, text) of every URDF file of example-robot-data and rtb-data, xacro expanded."""
    out = []
    erd = _site("example-robot-data")
    if erd is not None:
        robots = erd / "cmeel.prefix/share/example-robot-data/robots"
        for f in sorted(robots.rglob("*.urdf")):
            out.append((f"erd:{f.relative_to(robots)}", f.read_text(encoding="utf-8")))
    try:
        import rtbdata
    except ImportError:
        return out
    rtb = Path(rtbdata.__file__).parent
    for f in sorted(rtb.rglob("*.urdf")):
        out.append((f"rtb:{f.relative_to(rtb)}", f.read_text(encoding="utf-8")))
    for f in sorted(rtb.rglob("*.xacro")):
        if "macro" in f.name or "common" in f.name or f.name.endswith((".bak",)):
            continue
        text = _xacro(f, rtb / "xacro")
        if text is not None:
            out.append((f"rtb-xacro:{f.relative_to(rtb)}", text))
    return out


def _xacro(path: Path, share: Path) -> str | None:
    """The URDF text of a xacro file (``$(find pkg)`` looked up under ``share``), or None."""
    try:
        import xacro
        from xacro import substitution_args
    except ImportError:
        return None

    def find(pkg):  # ROS packages laid out under other folder names ("kuka_kr3_support")
        for name in (pkg, pkg.removesuffix("_support"),
                     pkg.replace("_support", "_description")):
            hits = [p for p in share.rglob(name) if p.is_dir()]
            if hits:
                return str(hits[0])
        return str(share / pkg)

    substitution_args._eval_find = find
    try:
        with open(os.devnull, "w") as null, _redirect(null):
            doc = xacro.process_file(str(path))
        return doc.toxml()
    except Exception:  # noqa: BLE001 - a xacro file that needs a missing package is skipped
        return None


class _redirect:
    def __init__(self, f):
        self.f = f

    def __enter__(self):
        self.old = sys.stderr, sys.stdout
        sys.stderr = sys.stdout = self.f

    def __exit__(self, *a):
        sys.stderr, sys.stdout = self.old


def chains(text: str) -> list[tuple[str, bool, str]]:
    """(leaf link, expected to load, why not) of every root-to-leaf chain with a moving joint,
    read off the XML independently of kinestat's parser."""
    root = ET.fromstring(text.lstrip("\ufeff").encode())
    strip = {e: e.tag.rsplit("}", 1)[-1] for e in root.iter() if isinstance(e.tag, str)}
    for e, t in strip.items():
        e.tag = t
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    parents = {j.find("parent").get("link") for j in root.findall("joint")}
    out = []
    for leaf in [lk.get("name") for lk in root.findall("link")]:
        if leaf in parents:
            continue
        link, moving, why = leaf, 0, ""
        while link in by_child:
            j = by_child[link]
            kind = j.get("type")
            if kind in ("floating", "planar"):
                why = why or f"{kind} joint {j.get('name')}"
            elif kind != "fixed":
                moving += 1
                if j.find("mimic") is not None:
                    why = why or f"mimic joint {j.get('name')}"
            link = j.find("parent").get("link")
        if moving:
            out.append((leaf, not why, why))
    return out


# -- checks ---------------------------------------------------------------------------------
def _pin_q(pin, pm, model, q):
    qp = pin.neutral(pm)
    for name, v in zip([j.name for j in model.joints], q, strict=True):
        jm = pm.joints[pm.getJointId(name)]
        if jm.nq == 2:
            qp[jm.idx_q:jm.idx_q + 2] = [math.cos(v), math.sin(v)]
        else:
            qp[jm.idx_q] = v
    return qp


def random_q(model, rng, k):
    """Uniform within the limits, at most two turns (revolute) or 10 m (prismatic) from 0:
    limits of ±1e6 would compare rounding of sin(1e6), not kinematics."""
    span = np.where(model.prismatic, 10.0, 4 * PI)
    lo = np.maximum(np.where(np.isfinite(model.lower), model.lower, -PI), -span)
    hi = np.minimum(np.where(np.isfinite(model.upper), model.upper, PI), span)
    return lo + (hi - lo) * rng.random((k, model.n))


class Oracle:
    """Pinocchio's model of a URDF text: the tip pose and space Jacobian [ω; v_O]."""

    def __init__(self, text: str, model, tip: str):
        import pinocchio as pin

        self.pin, self.model = pin, model
        self.pm = pin.buildModelFromXML(text.lstrip("\ufeff"))
        self.data = self.pm.createData()
        self.fid = self.pm.getFrameId(tip)
        self.cols = [self.pm.joints[self.pm.getJointId(j.name)].idx_v for j in model.joints]

    def fk(self, q):
        pin = self.pin
        pin.framesForwardKinematics(self.pm, self.data, _pin_q(pin, self.pm, self.model, q))
        return self.data.oMf[self.fid].homogeneous

    def jacobian(self, q):
        pin = self.pin
        qp = _pin_q(pin, self.pm, self.model, q)
        J = pin.computeFrameJacobian(self.pm, self.data, qp, self.fid, pin.ReferenceFrame.WORLD)
        return np.vstack([J[3:], J[:3]])[:, self.cols]


def check_fk(model, oracle, rng, k) -> dict:
    qs = random_q(model, rng, k)
    T, J = kinestat.fk(model, qs), kinestat.jacobian(model, qs)
    fk_err = max(float(np.abs(T[i] - oracle.fk(q)).max()) for i, q in enumerate(qs))
    j_err = max(float(np.abs(J[i] - oracle.jacobian(q)).max()) for i, q in enumerate(qs))
    return {"fk_err": fk_err, "jac_err": j_err}


def _distinct(sols, tol=1e-6):
    out: list[np.ndarray] = []
    for s in sols:
        if all(np.max(np.abs(np.mod(s - d + PI, 2 * PI) - PI)) > tol for d in out):
            out.append(s)
    return out


def _residual(oracle, q, T):
    F = oracle.fk(q)
    return max(float(np.linalg.norm(F[:3, 3] - T[:3, 3])),
               float(np.linalg.norm(F[:3, :3] - T[:3, :3])))


def check_ik_all(model, oracle, rng, k, locked_j=None) -> dict:
    """Every ik_all solution against Pinocchio's FK, completeness, counts vs EAIK/ik-geo."""
    from ik_all import peer_eaik_hp, peer_ikgeo

    from kinestat.serial.analytic import ik_all

    qs = random_q(model, rng, k)
    locked = None
    if locked_j is not None:
        qs[:, locked_j] = qs[0, locked_j]
        locked = {locked_j: float(qs[0, locked_j])}
    T = kinestat.fk(model, qs)
    try:
        res = ik_all(model, T, locked=locked)
    except KinestatError as exc:
        return {"ik_all": f"refused: {exc}"[:160]}
    worst, complete, sols_all = 0.0, 0, []
    for i, q in enumerate(qs):
        sols = res.q[i][res.valid[i]]
        sols_all.append(sols)
        for s in sols:
            worst = max(worst, _residual(oracle, s, T[i]))
        wrap = np.abs(np.mod(sols - q + PI, 2 * PI) - PI)
        wrap[:, model.prismatic] = np.abs((sols - q)[:, model.prismatic])
        complete += bool(len(sols)) and bool(np.min(np.max(wrap, axis=1)) < 1e-6)
    out = {"method": res.method, "ik_residual": worst, "complete": complete / k,
           "mean_n": float(res.n_solutions.mean())}
    if model.prismatic.any():
        return out
    peers = {}
    try:
        if locked is None:
            peers["eaik"] = peer_eaik_hp(model)
            if res.method in ("pieper", "three-parallel"):
                peers["ik-geo"] = peer_ikgeo(model, res.method)
        else:
            peers["eaik"] = peer_eaik_hp(model, list(locked.items()), keep_ls=True)
    except Exception as exc:  # noqa: BLE001 - a peer that cannot take the arm is reported
        out["peer_error"] = f"{type(exc).__name__}: {exc}"[:120]
    for name, call in peers.items():
        if call is None:
            out[name] = "n/a"
            continue
        same = lacks = 0
        for i in range(k):
            theirs = _distinct([s for s in call(T[i])
                                if _residual(oracle, np.asarray(s), T[i]) < 1e-6])
            mine = sols_all[i]
            same += len(theirs) == len(_distinct(mine))
            # a peer's approximate solution (1-D searches) can sit ~1e-6 from an exact one
            lacks += sum(1 for s in theirs if not len(mine) or np.min(np.max(
                np.abs(np.mod(mine - s + PI, 2 * PI) - PI), axis=1)) > 1e-4)
        out[name] = same / k
        out[f"{name}_solutions_kinestat_lacks"] = lacks
    return out


def check_numerical(model, oracle, rng, k) -> dict:
    qs = random_q(model, rng, k)
    T = kinestat.fk(model, qs)
    r = kinestat.ik(model, T)
    false_ok = 0
    for i in np.flatnonzero(r.success):
        if _residual(oracle, r.q[i], T[i]) > 1e-7 or not _within(model, r.q[i]):
            false_ok += 1
    far = T.copy()
    far[:, :3, 3] += 100.0 * (1.0 + np.abs(T[:, :3, 3]).max())
    r_far = kinestat.ik(model, far[:2], restarts=2)
    return {"num_success": float(r.success.mean()), "num_false_success": false_ok,
            "num_unreachable_success": int(r_far.success.sum())}


def _within(model, q):
    return bool(np.all(q >= model.lower - 1e-12) and np.all(q <= model.upper + 1e-12))


# -- one chain ------------------------------------------------------------------------------
def run_chain(name, text, tip, expect_load, why, rng, quick, base=None) -> dict:
    row = {"robot": name, "tip": tip, "expect": "load" if expect_load else f"refuse ({why})"}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = from_urdf(text, tip=tip, base=base)
    except KinestatError as exc:
        row["load"] = f"error: {exc}"[:200]
        if expect_load:
            row["fail"] = ["refused a valid chain"]
        return row
    except Exception as exc:  # noqa: BLE001 - that is the finding
        row["load"] = f"CRASH {type(exc).__name__}: {exc}"[:200]
        row["fail"] = ["non-kinestat exception"]
        return row
    row["load"], row["n"] = "ok", model.n
    if not expect_load:
        row["fail"] = [f"accepted an invalid chain ({why})"]
        return row
    try:
        oracle = Oracle(text, model, tip)
    except Exception as exc:  # noqa: BLE001 - Pinocchio refuses the file: nothing to compare
        row["oracle"] = f"pinocchio: {type(exc).__name__}"
        return row
    fails = []
    row.update(check_fk(model, oracle, rng, 5 if quick else 20))
    if row["fk_err"] > FK_TOL or row["jac_err"] > FK_TOL:
        fails.append("fk/jacobian")
    if model.n == 6 or model.n == 7:
        for lj in ([None] if model.n == 6 else [2] if quick else [2, 6]):
            ik = check_ik_all(model, oracle, rng, 4 if quick else 12, lj)
            row[f"ik_all{'' if lj is None else f'_lock{lj + 1}'}"] = ik
            fails += _ik_fails(ik, lj)
    if model.n <= 7:
        row.update(check_numerical(model, oracle, rng, 4 if quick else 10))
        if row["num_false_success"] or row["num_unreachable_success"]:
            fails.append("numerical ik false success")
    if fails:
        row["fail"] = fails
    return row


def _ik_fails(ik: dict, lj) -> list[str]:
    tag = "ik_all" if lj is None else f"ik_all lock{lj + 1}"
    if "ik_residual" not in ik:
        return [] if "refused" in ik.get("ik_all", "") else [f"{tag} crashed"]
    out = []
    if ik["ik_residual"] > IK_TOL:
        out.append(f"{tag} residual")
    if ik["complete"] < 1.0:
        out.append(f"{tag} incomplete")
    for peer in ("eaik", "ik-geo"):  # a peer finding fewer verified solutions is its limit
        if ik.get(f"{peer}_solutions_kinestat_lacks"):
            out.append(f"{tag} lacks {peer}'s solutions")
    return out


def main(argv=None) -> int:
    from urdf_zoo_variants import variants

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer chains and configurations")
    ap.add_argument("--json", help="write every row to this file")
    ap.add_argument("--only", help="only robots whose name contains this text")
    a = ap.parse_args(argv)
    rng = np.random.default_rng(20261207)
    rows, t0 = [], time.perf_counter()
    files = real_files()
    jobs = []
    for name, text in files:
        try:
            cs = chains(text)
        except ET.ParseError:  # not XML: kinestat must say so
            cs = [(None, False, "not XML")]
        if a.quick:
            cs = cs[:2]
        jobs += [(name, text, leaf, ok, why, None) for leaf, ok, why in cs]
    jobs += variants(files)
    for name, text, tip, ok, why, base in jobs:
        if a.only and a.only not in name:
            continue
        row = run_chain(name, text, tip, ok, why, rng, a.quick, base)
        rows.append(row)
        if "fail" in row:
            print(f"FAIL {name} tip={tip}: {row['fail']} "
                  f"{ {k: v for k, v in row.items() if k not in ('robot', 'tip', 'fail')} }",
                  flush=True)
    _summary(rows, len(files), time.perf_counter() - t0)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1, default=str))
    return 1 if any("fail" in r for r in rows) else 0


def _summary(rows, n_files, seconds) -> None:
    loaded = [r for r in rows if r.get("load") == "ok"]
    fk = [r["fk_err"] for r in loaded if "fk_err" in r]
    jac = [r["jac_err"] for r in loaded if "jac_err" in r]
    print(f"# {n_files} real files, {len({r['robot'] for r in rows})} robots/variants, "
          f"{len(rows)} chains, {len(loaded)} loaded, "
          f"{sum(1 for r in rows if r.get('load', '').startswith('error'))} refused, "
          f"{sum(1 for r in rows if 'oracle' in r)} without a Pinocchio model; {seconds:.0f} s")
    if fk:
        print(f"# FK vs Pinocchio: worst {max(fk):.1e} over {len(fk)} chains; Jacobian "
              f"worst {max(jac):.1e}")
    for key in ("ik_all", "ik_all_lock3", "ik_all_lock7"):
        ik = [r[key] for r in loaded if isinstance(r.get(key), dict) and "ik_residual" in r[key]]
        if not ik:
            continue
        for peer in ("eaik", "ik-geo"):
            agree = [x[peer] for x in ik if isinstance(x.get(peer), float)]
            if agree:
                print(f"# {key}: {peer} count agreement {np.mean(agree):.3f} on {len(agree)} "
                      f"chains ({sum(1 for v in agree if v == 1.0)} all poses equal)")
        print(f"# {key}: {len(ik)} chains, worst residual "
              f"{max(x['ik_residual'] for x in ik):.1e}, complete on "
              f"{sum(1 for x in ik if x['complete'] == 1.0)}")
    num = [r for r in loaded if "num_success" in r]
    if num:
        print(f"# numerical ik: mean success {np.mean([r['num_success'] for r in num]):.3f} "
              f"on {len(num)} chains, false successes "
              f"{sum(r['num_false_success'] + r['num_unreachable_success'] for r in num)}")
    print(f"# failing chains: {sum(1 for r in rows if 'fail' in r)}")


if __name__ == "__main__":
    sys.exit(main())
