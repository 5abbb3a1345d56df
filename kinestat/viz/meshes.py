"""A URDF model's visual meshes in the viewer: each mesh rides on one chain frame.

The page draws mesh ``m`` at ``F_k(q) · offset · diag(scale)``, ``F_k`` the chain frame
``C0 Z(q1) C1 … Z(qk) Ck`` of the joint that carries the mesh's link (``k = 0``: the base, no
joint moves it). ``offset`` is found once at the zero configuration from the URDF's own link
poses (:func:`kinestat.io.urdf_visuals.link_poses`): ``offset = F_k(0)^-1 · L(0) · V``, ``L`` the
link's pose relative to the model's base link and ``V`` the visual's origin, lengths in the
model's unit. Scene key ``meshes``: ``[{"frame", "offset", "scale", "format", "path", "link",
"color"}]``; ``mesh_messages``: why a mesh is not drawn (the stick figure stands in).
"""

from __future__ import annotations

import os

import numpy as np

from kinestat.io.urdf import metres_per_unit
from kinestat.io.urdf_visuals import link_poses, read_visuals
from kinestat.mechanism.chain import ChainModel

__all__ = ["urdf_meshes", "MESH_MODES"]

#: how a page carries its meshes: inside the page, as links to the files, or not at all
MESH_MODES = ("embed", "link", "none")


def _carriers(root, joint_names: list[str], base_link: str) -> dict[str, int | None]:
    """Per link: the 1-based index of the model joint that moves it (0: none; None: a joint
    not in the model moves it, it cannot be drawn)."""
    index = {n: i + 1 for i, n in enumerate(joint_names)}
    kids: dict[str, list] = {}
    parent_of = {}
    for j in root.findall("joint"):
        p, c = j.find("parent"), j.find("child")
        if p is not None and c is not None:
            kids.setdefault(p.get("link"), []).append(j)
            parent_of[c.get("link")] = (p.get("link"), j)
    top = base_link
    while top in parent_of:  # links above the base ride with it (they are fixed in space)
        top = parent_of[top][0]
    out: dict[str, int | None] = {top: 0}
    stack = [top]
    while stack:
        link = stack.pop()
        for j in kids.get(link, []):
            child = j.find("child").get("link")
            name, fixed = str(j.get("name")), j.get("type") == "fixed"
            out[child] = out[link] if fixed else index.get(name)
            stack.append(child)
    return out


def urdf_meshes(path: str | os.PathLike, model: ChainModel, *, base: str | None = None,
                scale: float | None = None,
                length_unit: str | None = None) -> tuple[list[dict], list[str]]:
    """The mesh records of a model loaded from the URDF at ``path`` with these options (as
    :func:`kinestat.load`), and the messages on meshes that cannot be drawn."""
    visuals, root = read_visuals(path)
    s = float(scale) if scale is not None else 1.0 / metres_per_unit(length_unit or "m")
    L0 = link_poses(root)
    names = [j.name for j in model.joints]
    children = {c.get("link") for c in root.findall("joint/child")}
    roots = [lk.get("name") for lk in root.findall("link") if lk.get("name") not in children]
    base_link = base or (roots[0] if roots else next(iter(L0)))
    carriers = _carriers(root, names, base_link)
    Binv = np.linalg.inv(L0[base_link])
    F0 = [np.asarray(model.constants[0], dtype=float)]
    for C in model.constants[1:]:
        F0.append(F0[-1] @ np.asarray(C, dtype=float))
    out, messages = [], []
    for v in visuals:
        if v.missing:
            messages.append(v.missing)
            continue
        k = carriers.get(v.link)
        if k is None:
            messages.append(f"link {v.link!r} is moved by a joint outside the model's chain; "
                            "its mesh is not drawn")
            continue
        W = Binv @ L0[v.link] @ v.origin
        W[:3, 3] *= s
        offset = W if k == 0 else np.linalg.inv(F0[k]) @ W
        out.append({"frame": int(k), "offset": offset.tolist(),
                    "scale": [float(x) * s for x in v.scale], "format": v.fmt,
                    "path": str(v.path), "link": v.link, "color": v.color})
    return out, messages
