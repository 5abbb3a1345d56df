/* kinestat 3D viewer: draws the JSON scene embedded in the page (see docs/viewer.md).
 * Needs the global THREE (three.js + OrbitControls, vendored in kinestat/data/viewer/).
 * Coordinates are the model's (z up); poses are 4x4 row-major nested arrays. */
(function () {
  "use strict";
  const status = { ready: false, errors: [], step: 0, fk_frames: null };
  const origError = console.error.bind(console);
  console.error = function (...args) { status.errors.push(args.map(String).join(" ")); origError(...args); };
  window.addEventListener("error", (e) => status.errors.push(String(e.message || e)));
  window.addEventListener("unhandledrejection", (e) => status.errors.push(String(e.reason)));

  const scene = JSON.parse(document.getElementById("kinestat-scene").textContent);
  const S = scene.scale || 1;

  // ---- 4x4 row-major arithmetic (forward kinematics C0 Z(q1) C1 ... Z(qn) Cn) ----------------
  function mul(A, B) {
    const C = [[0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]];
    for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) {
      let s = 0; for (let k = 0; k < 4; k++) s += A[i][k] * B[k][j]; C[i][j] = s;
    }
    return C;
  }
  function jointMotion(kind, pitch, q) {   // revolute Rz(q), prismatic Tz(q), screw Rz(q) Tz(h q)
    const a = kind === "prismatic" ? 0 : q, c = Math.cos(a), s = Math.sin(a);
    const z = kind === "prismatic" ? q : (kind === "screw" ? pitch * q : 0);
    return [[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, z], [0, 0, 0, 1]];
  }
  function chainFrames(robot, q) {          // [F_0 .. F_n], F_{i-1} is joint i's frame
    const C = robot.constants; let T = C[0]; const out = [T];
    for (let i = 0; i < q.length; i++) {
      T = mul(mul(T, jointMotion(robot.kinds[i], robot.pitches[i], q[i])), C[i + 1]); out.push(T);
    }
    return out;
  }
  function toMatrix4(P) {
    const m = new THREE.Matrix4();
    m.set(P[0][0], P[0][1], P[0][2], P[0][3], P[1][0], P[1][1], P[1][2], P[1][3],
      P[2][0], P[2][1], P[2][2], P[2][3], P[3][0], P[3][1], P[3][2], P[3][3]);
    return m;
  }
  const v3 = (p) => new THREE.Vector3(p[0], p[1], p[2]);

  // ---- three.js set-up ---------------------------------------------------------------------
  const view = document.getElementById("view");
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setSize(view.clientWidth, view.clientHeight);
  view.appendChild(renderer.domElement);
  const world = new THREE.Scene();
  world.background = new THREE.Color(0xf4f5f7);
  const camera = new THREE.PerspectiveCamera(40, view.clientWidth / view.clientHeight, S * 1e-3, S * 1e3);
  camera.up.set(0, 0, 1);
  world.add(new THREE.HemisphereLight(0xffffff, 0x8899aa, 1.6));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6); sun.position.set(1, -2, 3); world.add(sun);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.addEventListener("change", render);

  const staticGroup = new THREE.Group(), robotGroup = new THREE.Group(), stepGroup = new THREE.Group();
  world.add(staticGroup, robotGroup, stepGroup);

  function material(color, opacity) {
    const m = new THREE.MeshStandardMaterial({ color: color || "#888888", roughness: 0.6, metalness: 0.1,
      side: THREE.DoubleSide });
    if (opacity !== undefined && opacity < 1) { m.transparent = true; m.opacity = opacity; m.depthWrite = false; }
    return m;
  }
  function segment(a, b, r, color) {
    const A = v3(a), B = v3(b), d = new THREE.Vector3().subVectors(B, A), L = d.length();
    if (L < 1e-12) return new THREE.Group();
    const mesh = new THREE.Mesh(new THREE.CylinderGeometry(r, r, L, 16), material(color));
    mesh.position.copy(A).addScaledVector(d, 0.5);
    mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), d.normalize());
    return mesh;
  }
  function arrow(origin, vector, color) {
    const d = v3(vector), L = d.length();
    if (L < 1e-12) return new THREE.Group();
    return new THREE.ArrowHelper(d.clone().normalize(), v3(origin), L, new THREE.Color(color),
      Math.min(0.25 * L, 0.08 * S), Math.min(0.12 * L, 0.04 * S));
  }
  function polyline(points, color, dashed) {
    const g = new THREE.BufferGeometry().setFromPoints(points.map(v3));
    const m = dashed ? new THREE.LineDashedMaterial({ color: color, dashSize: 0.04 * S, gapSize: 0.02 * S })
      : new THREE.LineBasicMaterial({ color: color });
    const line = new THREE.Line(g, m); if (dashed) line.computeLineDistances();
    return line;
  }
  function polygon(points, color, opacity) {
    const P = points.map(v3), pos = [];
    for (let i = 1; i + 1 < P.length; i++) pos.push(...P[0].toArray(), ...P[i].toArray(), ...P[i + 1].toArray());
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.Float32BufferAttribute(pos, 3)); g.computeVertexNormals();
    const grp = new THREE.Group();
    grp.add(new THREE.Mesh(g, material(color, opacity)));
    grp.add(polyline(points.concat([points[0]]), "#333333"));
    return grp;
  }
  function frameAxes(P, size) { const a = new THREE.AxesHelper(size); a.matrixAutoUpdate = false; a.matrix.copy(toMatrix4(P)); return a; }
  function drawItem(it) {
    switch (it.type) {
      case "segment": return segment(it.a, it.b, it.radius || 0.01 * S, it.color);
      case "polyline": return polyline(it.points, it.color, it.dashed);
      case "polygon": return polygon(it.points, it.color, it.opacity);
      case "arrow": return arrow(it.origin, it.vector, it.color);
      case "line": {
        const p = v3(it.point), u = v3(it.direction).normalize(), h = (it.length || 2 * S) / 2;
        return polyline([p.clone().addScaledVector(u, -h).toArray(), p.clone().addScaledVector(u, h).toArray()], it.color, true);
      }
      case "marker": {
        const m = new THREE.Mesh(new THREE.SphereGeometry(it.radius || 0.02 * S, 20, 12), material(it.color));
        m.position.copy(v3(it.at)); return m;
      }
      case "frame": return frameAxes(it.pose, it.size || 0.2 * S);
      default: throw new Error("kinestat viewer: unknown item type " + it.type);
    }
  }
  function clear(group) {
    for (const c of [...group.children]) {
      group.remove(c);
      c.traverse((o) => { if (o.geometry) o.geometry.dispose(); if (o.material) o.material.dispose(); });
    }
  }

  // ---- the robot, drawn from its frames ------------------------------------------------------
  const showFrames = document.getElementById("show-frames");
  function drawRobot(robot, q) {
    clear(robotGroup);
    const F = chainFrames(robot, q), r = 0.025 * S;
    const pos = (P) => [P[0][3], P[1][3], P[2][3]];
    for (let i = 0; i < q.length; i++) {
      const Fi = mul(F[i], jointMotion(robot.kinds[i], robot.pitches[i], q[i]));
      const p0 = pos(F[i]), z = [F[i][0][2], F[i][1][2], F[i][2][2]], p1 = pos(F[i + 1]);
      const along = (p1[0] - p0[0]) * z[0] + (p1[1] - p0[1]) * z[1] + (p1[2] - p0[2]) * z[2];
      const elbow = [p0[0] + along * z[0], p0[1] + along * z[1], p0[2] + along * z[2]];
      robotGroup.add(segment(p0, elbow, 0.6 * r, "#5b6770"), segment(elbow, p1, 0.6 * r, "#5b6770"));
      const kind = robot.kinds[i], M = toMatrix4(Fi);
      const joint = kind === "prismatic"
        ? new THREE.Mesh(new THREE.BoxGeometry(2.4 * r, 2.4 * r, 5 * r), material("#e39b2d"))
        : new THREE.Mesh(new THREE.CylinderGeometry(1.5 * r, 1.5 * r, 4 * r, 24), material("#2d7fe3"));
      if (kind !== "prismatic") joint.geometry.rotateX(Math.PI / 2);   // cylinder along local z
      joint.matrixAutoUpdate = false; joint.matrix.copy(M); robotGroup.add(joint);
      if (kind === "screw") {                                          // helix mark of a screw joint
        const pts = []; for (let t = 0; t <= 96; t++) { const a = t / 96 * 6 * Math.PI;
          pts.push(new THREE.Vector3(2.2 * r * Math.cos(a), 2.2 * r * Math.sin(a), -2.5 * r + 5 * r * t / 96)); }
        const h = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: "#c0392b" }));
        h.matrixAutoUpdate = false; h.matrix.copy(M); robotGroup.add(h);
      }
      if (showFrames.checked) robotGroup.add(frameAxes(F[i], 5 * r));
    }
    robotGroup.add(frameAxes(F[q.length], 7 * r));
    status.fk_frames = F;
    document.getElementById("pose").textContent = "end pose (" + (scene.length_unit || "") + ")\n" +
      F[q.length].map((row) => row.map((x) => x.toFixed(4).padStart(11)).join("")).join("\n");
    return F;
  }

  // ---- legend, info, sliders, timeline --------------------------------------------------------
  function legend(items) {
    const el = document.getElementById("legend"); el.innerHTML = "";
    for (const it of items) {
      if (!it.label) continue;
      const row = document.createElement("div"), sw = document.createElement("span");
      sw.className = "swatch"; sw.style.background = it.color || "#888";
      row.append(sw, document.createTextNode(it.label)); el.appendChild(row);
    }
  }
  function setInfo(lines) { document.getElementById("info").textContent = (lines || []).join("\n"); }
  document.getElementById("title").textContent = scene.title || "kinestat";

  for (const it of scene.items) staticGroup.add(drawItem(it));
  const robot = scene.robot;
  let q = robot ? robot.q.slice() : null;

  if (robot && robot.live) {
    const panel = document.getElementById("sliders");
    robot.kinds.forEach((kind, i) => {
      const rev = kind !== "prismatic";
      const lo = robot.lower[i] ?? (rev ? -Math.PI : -S), hi = robot.upper[i] ?? (rev ? Math.PI : S);
      const k = rev ? 180 / Math.PI : 1;
      const row = document.createElement("label"), inp = document.createElement("input"), out = document.createElement("span");
      inp.type = "range"; inp.min = lo * k; inp.max = hi * k; inp.step = (hi - lo) * k / 1000; inp.value = q[i] * k;
      inp.id = "joint" + (i + 1);
      out.textContent = (q[i] * k).toFixed(2) + (rev ? "°" : "");
      inp.addEventListener("input", () => {
        q[i] = Number(inp.value) / k; out.textContent = Number(inp.value).toFixed(2) + (rev ? "°" : "");
        drawRobot(robot, q); render();
      });
      row.append(document.createTextNode(robot.joint_names[i] + " "), inp, out); panel.appendChild(row);
    });
  }

  function setQ(values) {   // exact joint values (IK answers): the sliders only display them
    q = values.slice();
    robot.kinds.forEach((kind, i) => {
      const k = kind !== "prismatic" ? 180 / Math.PI : 1, el = document.getElementById("joint" + (i + 1));
      el.value = q[i] * k; el.nextSibling.textContent = (q[i] * k).toFixed(2) + (kind !== "prismatic" ? "°" : "");
    });
    drawRobot(robot, q); render();
  }

  const steps = scene.steps || [];
  function showStep(k) {
    status.step = k;
    const st = steps[k];
    clear(stepGroup);
    for (const it of st.items || []) stepGroup.add(drawItem(it));
    if (robot && st.q) { q = st.q.slice(); drawRobot(robot, q); }
    document.getElementById("step-label").textContent = st.label || ("step " + k);
    setInfo((scene.info || []).concat(st.info || []));
    legend(scene.items.concat(st.items || []));
    render();
  }
  const timeline = document.getElementById("timeline"), play = document.getElementById("play");
  let timer = null;
  if (steps.length) {
    document.getElementById("player").hidden = false;
    timeline.max = steps.length - 1; timeline.value = 0;
    timeline.addEventListener("input", () => showStep(Number(timeline.value)));
    play.addEventListener("click", () => {
      if (timer) { clearInterval(timer); timer = null; play.textContent = "play"; return; }
      play.textContent = "pause";
      const dt = Math.max(16, Math.min(400, 6000 / steps.length));
      timer = setInterval(() => {
        const k = (Number(timeline.value) + 1) % steps.length; timeline.value = k; showStep(k);
        if (k === steps.length - 1) { clearInterval(timer); timer = null; play.textContent = "play"; }
      }, dt);
    });
  }
  showFrames.checked = !!scene.show_frames;
  showFrames.addEventListener("change", () => { if (robot) drawRobot(robot, q); render(); });

  // ---- IK request (served pages only): a target box and a draggable target gizmo -------------
  const ikPanel = document.getElementById("ik");
  let gizmo = null, ikTo = null;
  if (robot && robot.live && location.protocol.startsWith("http") && scene.ik_url) {
    ikPanel.hidden = false;
    const targetBox = document.getElementById("ik-target");
    const end0 = chainFrames(robot, q)[q.length];
    const showTarget = (t) => { targetBox.value = t.map((x) => x.toFixed(3)).join(","); };
    showTarget([end0[0][3], end0[1][3], end0[2][3]]);
    ikTo = async (t) => {    // ask the server for every solution putting the end origin at t
      showTarget(t);
      const res = await fetch(scene.ik_url, { method: "POST", headers: { "Content-Type": "application/json" },
        body: JSON.stringify({ q: q, target: t }) });
      const ans = await res.json();
      const out = document.getElementById("ik-out"), pick = document.getElementById("ik-pick");
      pick.innerHTML = "";
      const outside = ans.outside_limits ? " (" + ans.outside_limits + " more outside the joint limits)" : "";
      if (!ans.solutions || !ans.solutions.length) {
        out.textContent = (ans.error || "no solution within the joint limits") + outside; pick.hidden = true; return ans;
      }
      out.textContent = ans.solutions.length + " solution(s), nearest first" + outside;
      ans.solutions.forEach((sol, k) => { const o = document.createElement("option"); o.value = k;
        o.textContent = "solution " + (k + 1); pick.appendChild(o); });
      pick.hidden = false;
      pick.onchange = () => setQ(ans.solutions[Number(pick.value)]);
      setQ(ans.solutions[0]);
      return ans;
    };
    document.getElementById("ik-go").addEventListener("click", () => {
      const t = targetBox.value.split(",").map(Number);
      target.position.set(t[0], t[1], t[2]); ikTo(t);
    });
    // the gizmo: drag the orange ball (three.js TransformControls); letting go asks for IK
    const target = new THREE.Mesh(new THREE.SphereGeometry(0.03 * S, 20, 12), material("#ff7f0e"));
    target.position.set(end0[0][3], end0[1][3], end0[2][3]);
    world.add(target);
    gizmo = new THREE.TransformControls(camera, renderer.domElement);
    gizmo.setSize(0.8); gizmo.attach(target); world.add(gizmo.getHelper());
    gizmo.addEventListener("change", () => render());
    gizmo.addEventListener("dragging-changed", (e) => { controls.enabled = !e.value; });
    gizmo.addEventListener("objectChange", () => showTarget(target.position.toArray()));
    gizmo.addEventListener("mouseUp", () => ikTo(target.position.toArray()));
  }

  function render() { renderer.render(world, camera); }
  function fit() {
    const box = new THREE.Box3();   // the drawn content only (not the IK gizmo's helper plane)
    for (const g of [staticGroup, robotGroup, stepGroup]) box.expandByObject(g);
    if (box.isEmpty()) box.set(new THREE.Vector3(-S, -S, -S), new THREE.Vector3(S, S, S));
    let c = box.getCenter(new THREE.Vector3()), r = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);
    if (scene.focus) { c = v3(scene.focus.point); r = scene.focus.radius; }   // e.g. the tool of the cell
    const d = r / Math.sin(camera.fov * Math.PI / 360);
    camera.position.copy(c).add(new THREE.Vector3(0.9, -1.4, 0.8).normalize().multiplyScalar(d));
    camera.near = d / 100; camera.far = d * 100; camera.updateProjectionMatrix();
    controls.target.copy(c); controls.update();
  }
  window.addEventListener("resize", () => {
    renderer.setSize(view.clientWidth, view.clientHeight);
    camera.aspect = view.clientWidth / view.clientHeight; camera.updateProjectionMatrix(); render();
  });

  // "#step=N" in the address opens the animation at step N (links, screenshots)
  const wanted = /step=(\d+)/.exec(location.hash || "");
  const first = wanted ? Math.min(Number(wanted[1]), Math.max(steps.length - 1, 0)) : 0;
  if (steps.length) { timeline.value = first; showStep(first); }
  else { if (robot) drawRobot(robot, q); setInfo(scene.info); legend(scene.items); }
  fit(); render();
  status.ready = true;
  status.load_ms = performance.now();   // since navigation start: parse, build, first render
  status.webgl = renderer.getContext() ? true : false;
  window.kinestatViewer = { scene: scene, status: status, showStep: showStep, chainFrames: chainFrames,
    gizmo: gizmo, ikTo: ikTo };
  document.getElementById("kinestat-status").textContent = JSON.stringify(status);
})();
