"""URDF visual meshes in the viewer: where each mesh is drawn equals the URDF's own kinematics,
mesh names resolve as ROS resolves them, a missing mesh is named and left to the stick figure."""

from __future__ import annotations

import base64
import json

import numpy as np
import pytest

import kinestat
from kinestat.cli.main import main
from kinestat.io.urdf_visuals import link_poses, read_visuals, resolve_mesh
from kinestat.viz.html import extract_scene, render_html
from kinestat.viz.meshes import urdf_meshes
from kinestat.viz.scene import model_scene
from tests.urdf_arms import ARMS, arm_path


@pytest.mark.parametrize("name", ["ur5", "panda", "kinova-j2s6s200", "z1"])
def test_meshes_ride_where_the_urdf_puts_them(name, rng):
    """At random joint values each mesh's pose (the chain frame that carries it times its
    offset) equals the product of the URDF's joint origins and axis motions, to 1e-9."""
    path, tip = arm_path(name), ARMS[name][1]
    m = kinestat.load(str(path), **({"tip": tip} if tip else {}))
    records, messages = urdf_meshes(path, m)
    assert records, messages
    visuals, root = read_visuals(path)
    origin = {(v.link, v.filename): v.origin for v in visuals}
    lo = np.where(np.isfinite(m.lower), m.lower, -np.pi)
    hi = np.where(np.isfinite(m.upper), m.upper, np.pi)
    for _ in range(3):
        q = rng.uniform(lo, hi)
        F = [np.asarray(m.constants[0])]
        for i in range(m.n):  # C0 Z(q1) C1 ... as the page computes it
            F.append(F[-1] @ _z(m.joints[i].kind, q[i]) @ np.asarray(m.constants[i + 1]))
        L = link_poses(root, {j.name: float(x) for j, x in zip(m.joints, q, strict=True)})
        children = {c.get("link") for c in root.findall("joint/child")}
        base = next(lk.get("name") for lk in root.findall("link")
                    if lk.get("name") not in children)
        for rec in records:
            page = (np.eye(4) if rec["frame"] == 0 else F[rec["frame"]]) @ np.asarray(
                rec["offset"])
            v = next(o for (lk, fn), o in origin.items() if lk == rec["link"]
                     and rec["path"].endswith(fn.split("/")[-1]))
            urdf = np.linalg.inv(L[base]) @ L[rec["link"]] @ v
            np.testing.assert_allclose(page, urdf, atol=1e-9, rtol=0)


def _z(kind: str, x: float) -> np.ndarray:
    T = np.eye(4)
    if kind == "prismatic":
        T[2, 3] = x
    else:
        c, s = np.cos(x), np.sin(x)
        T[:2, :2] = [[c, -s], [s, c]]
    return T


def test_lengths_follow_the_model_unit():
    """In millimetres the offsets' translations and the mesh scale are 1000 times larger."""
    path = arm_path("ur5")
    m, mm = kinestat.load(str(path), tip="tool0"), kinestat.load(str(path), tip="tool0",
                                                                length_unit="mm")
    a, _ = urdf_meshes(path, m)
    b, _ = urdf_meshes(path, mm, length_unit="mm")
    for ra, rb in zip(a, b, strict=True):
        np.testing.assert_allclose(np.asarray(rb["offset"])[:3, 3],
                                   1000 * np.asarray(ra["offset"])[:3, 3], atol=1e-9)
        np.testing.assert_allclose(rb["scale"], np.multiply(ra["scale"], 1000))


def test_package_and_relative_names_resolve(tmp_path, monkeypatch):
    share = tmp_path / "share" / "mypkg"
    (share / "meshes").mkdir(parents=True)
    (share / "urdf").mkdir()
    (share / "meshes" / "a.stl").write_bytes(b"solid a\nendsolid a\n")
    urdf_dir = share / "urdf"
    assert resolve_mesh("package://mypkg/meshes/a.stl", urdf_dir) == share / "meshes" / "a.stl"
    assert resolve_mesh("../meshes/a.stl", urdf_dir) == urdf_dir / ".." / "meshes" / "a.stl"
    assert resolve_mesh(f"file://{share}/meshes/a.stl", urdf_dir) == share / "meshes" / "a.stl"
    assert resolve_mesh("package://otherpkg/a.stl", urdf_dir) is None
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "share"))
    assert resolve_mesh("package://mypkg/meshes/a.stl", tmp_path) == share / "meshes" / "a.stl"


TWO_LINK = """<robot name="two">
  <link name="base"><visual><geometry><mesh filename="{a}"/></geometry></visual></link>
  <link name="arm"><visual><origin xyz="0.1 0 0" rpy="0 0 0.5"/>
    <geometry><mesh filename="{b}" scale="2 2 2"/></geometry></visual></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="-1" upper="1"/></joint>
</robot>"""


def test_missing_mesh_is_named_and_the_page_says_so(tmp_path, capsys):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "arm.stl").write_bytes(_stl_box())
    u = tmp_path / "two.urdf"
    u.write_text(TWO_LINK.format(a="meshes/nothere.stl", b="meshes/arm.stl"), encoding="utf-8")
    page = tmp_path / "two.html"
    assert main(["view", str(u), "--html", str(page)]) == 0
    html = page.read_text(encoding="utf-8")
    s = extract_scene(html)
    assert [r["link"] for r in s["meshes"]] == ["arm"]
    assert any("nothere.stl" in msg and "not found" in msg for msg in s["mesh_messages"])
    data = json.loads(html.split('id="kinestat-meshes">')[1].split("</script>")[0])
    assert base64.b64decode(data[s["meshes"][0]["data"]]) == _stl_box()
    # --meshes none: no mesh in the page, and the page says why
    assert main(["view", str(u), "--meshes", "none", "--html", str(page)]) == 0
    s = extract_scene(page.read_text(encoding="utf-8"))
    assert s["meshes"] == [] and "--meshes none" in s["mesh_messages"][-1]
    # --meshes link: file addresses, nothing embedded
    assert main(["view", str(u), "--meshes", "link", "--html", str(page)]) == 0
    html = page.read_text(encoding="utf-8")
    s = extract_scene(html)
    assert s["meshes"][0]["url"] == (tmp_path / "meshes" / "arm.stl").resolve().as_uri()
    assert 'id="kinestat-meshes">{}</script>' in html
    capsys.readouterr()
    assert main(["view", str(u), "--meshes", "inline", "--html", str(page)]) == 2
    assert "--meshes" in capsys.readouterr().err


def _stl_box() -> bytes:
    """A binary STL of one triangle (enough for the loader)."""
    import struct

    tri = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 0.05, 0, 0, 0, 0.05, 0, 0)
    return b"kinestat test".ljust(80, b" ") + struct.pack("<I", 1) + tri


def test_model_scene_keeps_mesh_records_out_of_other_models():
    s = model_scene(kinestat.load("puma762"))
    assert "meshes" not in s
    assert extract_scene(render_html(s, meshes="none")) == json.loads(json.dumps(s))
