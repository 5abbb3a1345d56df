/* kinestat 3D viewer: draws the JSON scene embedded in the page (see docs/viewer.md).
 * Needs the global THREE (three.js + OrbitControls, TransformControls and the STL, Collada and
 * OBJ loaders, vendored in kinestat/data/viewer/). Coordinates are the model's (z up); poses
 * are 4x4 row-major nested arrays. */
(function () {
  "use strict";
  const status = { ready: false, errors: [], step: 0, fk_frames: null, meshes: { loaded: 0, failed: [] },
    loader_notes: [] };
  const origError = console.error.bind(console);
  console.error = function (...args) { status.errors.push(args.map(String).join(" ")); origError(...args); };
  window.addEventListener("error", (e) => status.errors.push(String(e.message || e)));
  window.addEventListener("unhandledrejection", (e) => status.errors.push(String(e.reason)));

  const scene = JSON.parse(document.getElementById("kinestat-scene").textContent);
  const meshData = JSON.parse(document.getElementById("kinestat-meshes").textContent || "{}");
  const S = scene.scale || 1;
  const $ = (id) => document.getElementById(id);

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
  const view = $("view"), plotCanvas = $("plot");
  if (scene.series) { document.body.classList.add("has-plot"); plotCanvas.hidden = false; }
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
  const meshGroup = new THREE.Group(), groundGroup = new THREE.Group();
  world.add(groundGroup, staticGroup, robotGroup, meshGroup, stepGroup);

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
      case "line": {   // an axis: endless in principle, so it neither places the floor nor the camera
        const p = v3(it.point), u = v3(it.direction).normalize(), h = (it.length || 2 * S) / 2;
        const line = polyline([p.clone().addScaledVector(u, -h).toArray(), p.clone().addScaledVector(u, h).toArray()], it.color, true);
        line.userData.unbounded = true; return line;
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
  function ghost(obj, opacity) {   // every material of obj see-through (other assembly modes)
    obj.traverse((o) => {
      for (const m of [].concat(o.material || [])) { m.transparent = true; m.opacity = opacity; m.depthWrite = false; }
    });
  }

  // ---- text labels (world axes) --------------------------------------------------------------
  function textSprite(text, color, height) {
    const c = document.createElement("canvas"), g = c.getContext("2d"), px = 48;
    g.font = "bold " + px + "px sans-serif";
    c.width = Math.ceil(g.measureText(text).width) + 8; c.height = px + 8;
    g.font = "bold " + px + "px sans-serif"; g.fillStyle = color; g.textBaseline = "middle";
    g.fillText(text, 4, c.height / 2);
    const tex = new THREE.CanvasTexture(c); tex.colorSpace = THREE.SRGBColorSpace;
    const sp = new THREE.Sprite(new THREE.SpriteMaterial({ map: tex, depthTest: false }));
    sp.scale.set(height * c.width / c.height, height, 1); sp.renderOrder = 10;
    return sp;
  }
  function niceStep(x) {   // 1, 2 or 5 times a power of ten, near x
    const p = Math.pow(10, Math.floor(Math.log10(x))), f = x / p;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
  }

  // ---- the robot, drawn from its frames; its URDF meshes ride on the frames ------------------
  const showFrames = $("show-frames"), showStick = $("show-stick");
  const meshObjects = [];   // [{object, frame, offset (Matrix4 incl. scale)}]
  function drawRobot(robot, q) {
    clear(robotGroup);
    const F = chainFrames(robot, q), r = 0.025 * S;
    const pos = (P) => [P[0][3], P[1][3], P[2][3]];
    const stick = !meshObjects.length || showStick.checked;
    for (let i = 0; i < q.length && stick; i++) {
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
    }
    for (let i = 0; i < q.length; i++) if (showFrames.checked) robotGroup.add(frameAxes(F[i], 5 * r));
    robotGroup.add(frameAxes(F[q.length], 7 * r));
    for (const m of meshObjects) m.object.matrix.multiplyMatrices(toMatrix4(F[m.frame]), m.offset);
    status.fk_frames = F;
    $("pose").textContent = "end pose (" + (scene.length_unit || "") + ")\n" +
      F[q.length].map((row) => row.map((x) => x.toFixed(4).padStart(11)).join("")).join("\n");
    return F;
  }

  function b64bytes(b64) {
    const s = atob(b64), u = new Uint8Array(s.length);
    for (let i = 0; i < s.length; i++) u[i] = s.charCodeAt(i);
    return u;
  }
  async function loadMesh(rec) {   // a THREE.Object3D in the mesh file's own coordinates
    const fmt = rec.format, url = rec.url;
    const bytes = rec.data !== undefined ? b64bytes(meshData[rec.data]) : null;
    const text = () => new TextDecoder().decode(bytes);
    let obj;
    if (fmt === "stl") {
      const geo = bytes ? new THREE.STLLoader().parse(bytes.buffer) : await new THREE.STLLoader().loadAsync(url);
      obj = new THREE.Mesh(geo, material(rec.color || "#b8bec6"));
    } else if (fmt === "dae") {
      // the loader's notes on the file (its version, "Z-UP ... rotates the asset", undone below)
      // go to status.loader_notes, not the console
      const warn = console.warn, debug = console.debug;
      console.warn = console.debug = (...a) => status.loader_notes.push(a.map(String).join(" "));
      let dae;
      try { dae = bytes ? new THREE.ColladaLoader().parse(text(), "") : await new THREE.ColladaLoader().loadAsync(url); }
      finally { console.warn = warn; console.debug = debug; }
      if (!dae || !dae.scene) throw new Error("not a Collada file");
      obj = dae.scene; obj.rotation.set(0, 0, 0);   // URDF takes the file's coordinates as they are
    } else if (fmt === "obj") {
      obj = bytes ? new THREE.OBJLoader().parse(text()) : await new THREE.OBJLoader().loadAsync(url);
      obj.traverse((o) => { if (o.isMesh) o.material = material(rec.color || "#b8bec6"); });
    } else throw new Error("format " + fmt + " not drawn");
    return obj;
  }
  async function loadMeshes(robot) {
    const msgs = (scene.mesh_messages || []).slice();
    const jobs = (scene.meshes || []).map(async (rec) => {
      try {
        const inner = await loadMesh(rec), holder = new THREE.Group();
        inner.updateMatrix();
        holder.add(inner); holder.matrixAutoUpdate = false;
        const off = toMatrix4(rec.offset).multiply(new THREE.Matrix4().makeScale(...rec.scale));
        meshObjects.push({ object: holder, frame: rec.frame, offset: off });
        meshGroup.add(holder); status.meshes.loaded += 1;
      } catch (err) {
        status.meshes.failed.push(rec.link);
        msgs.push("link " + rec.link + ": mesh could not be loaded (" + (err && err.message ? err.message : err) +
          "); drawn as the stick figure");
      }
    });
    await Promise.all(jobs);
    if (msgs.length) { const el = $("mesh-status"); el.hidden = false; el.textContent = msgs.join("\n"); }
    if ((scene.meshes || []).length) $("stick-row").hidden = false;
    if (robot) drawRobot(robot, q);
  }

  // ---- the floor grid and the labelled world axes ------------------------------------------
  function contentBox() {
    const box = new THREE.Box3();
    world.updateMatrixWorld(true);
    for (const g of [staticGroup, robotGroup, meshGroup, stepGroup]) g.traverseVisible((o) => {
      if (!o.geometry || o.userData.unbounded) return;   // what is drawn: hidden modes do not count
      if (!o.geometry.boundingBox) o.geometry.computeBoundingBox();
      box.union(o.geometry.boundingBox.clone().applyMatrix4(o.matrixWorld));
    });
    for (const st of scene.steps || []) for (const f of st.frames || []) box.expandByPoint(v3([f.pose[0][3], f.pose[1][3], f.pose[2][3]]));
    if (box.isEmpty()) { box.set(new THREE.Vector3(-S, -S, -S), new THREE.Vector3(S, S, S)); box.nothing = true; }
    return box;
  }
  let floorInfo = null;
  function buildGround() {
    clear(groundGroup);
    const box = contentBox(), size = box.getSize(new THREE.Vector3());
    if (box.nothing) return;   // nothing drawn: nothing stands on a floor
    const extent = Math.max(size.x, size.y, 0.5 * size.z, 1e-9);
    const cell = niceStep(extent / 6), half = Math.ceil((0.75 * extent + Math.max(
      Math.abs(box.min.x), Math.abs(box.max.x), Math.abs(box.min.y), Math.abs(box.max.y)) * 0.25) / cell) * cell;
    const z = Math.min(box.min.z, 0) - 1e-3 * extent;
    const cx = Math.round((box.min.x + box.max.x) / 2 / cell) * cell, cy = Math.round((box.min.y + box.max.y) / 2 / cell) * cell;
    const grid = new THREE.GridHelper(2 * half, Math.round(2 * half / cell), 0x8a94a0, 0xc5ccd4);
    grid.rotation.x = Math.PI / 2; grid.position.set(cx, cy, z);
    const floor = new THREE.Mesh(new THREE.PlaneGeometry(2 * half, 2 * half),
      new THREE.MeshBasicMaterial({ color: 0xe6e9ed, transparent: true, opacity: 0.6, depthWrite: false, side: THREE.DoubleSide }));
    floor.position.set(cx, cy, z - 1e-4 * extent);
    groundGroup.add(floor, grid);
    const a = niceStep(0.2 * extent), axes = new THREE.AxesHelper(a);
    axes.position.set(0, 0, z); groundGroup.add(axes);
    [["x", "#d62728", [1, 0, 0]], ["y", "#2ca02c", [0, 1, 0]], ["z", "#1f77b4", [0, 0, 1]]].forEach(([t, c, d]) => {
      const sp = textSprite(t, c, 0.45 * a); sp.position.set(1.12 * a * d[0], 1.12 * a * d[1], z + 1.12 * a * d[2]); groundGroup.add(sp);
    });
    const u = scene.length_unit || "";
    const len = (x) => u ? x + " " + u : String(x);
    $("grid-note").textContent = "floor grid: " + len(cell) + " squares; world axes x y z (" + len(a) + ")";
    floorInfo = { z: z, centre: [cx, cy, z], half: half, cell: cell };
    status.floor = floorInfo;
  }

  // ---- legend, info, sliders, timeline --------------------------------------------------------
  function legend(items) {
    const el = $("legend"); el.innerHTML = "";
    const groups = new Map();
    for (const it of items) {
      if (!it.label) continue;
      const g = it.group || "scene";
      if (!groups.has(g)) groups.set(g, []);
      groups.get(g).push(it);
    }
    for (const [g, list] of groups) {
      const box = document.createElement("details"), sum = document.createElement("summary");
      box.open = list.length <= 8 || groups.size === 1;
      sum.textContent = g + " (" + list.length + ")"; box.appendChild(sum);
      for (const it of list) {
        const row = document.createElement("div"), sw = document.createElement("span"), tx = document.createElement("span");
        row.className = "row"; sw.className = "swatch"; sw.style.background = it.color || "#888";
        tx.textContent = it.label; row.append(sw, tx); box.appendChild(row);
      }
      el.appendChild(box);
    }
  }
  function runLength(xs) {   // "a×3 → b → p×56", as kinestat.viz.scene.run_length
    const runs = [];
    for (const x of xs) { if (runs.length && runs[runs.length - 1][0] === x) runs[runs.length - 1][1] += 1; else runs.push([x, 1]); }
    return runs.map(([x, n]) => n > 1 ? x + "×" + n : x).join(" → ");
  }
  function setInfo(lines) { $("info").textContent = (lines || []).join("\n"); }
  $("title").textContent = scene.title || "kinestat";
  $("title").title = scene.title || "";

  // the platform's assembly modes: one at a time, the others ghosted on demand
  const modeGroups = new Map(), modes = scene.modes || [];
  let modeShown = modes.length ? modes[0].index : null;
  for (const it of scene.items) {
    const obj = drawItem(it);
    if (it.mode !== undefined) {
      if (!modeGroups.has(it.mode)) { const g = new THREE.Group(); modeGroups.set(it.mode, g); staticGroup.add(g); }
      modeGroups.get(it.mode).add(obj);
    } else staticGroup.add(obj);
  }
  function showMode(k) {
    modeShown = k;
    const ghosts = $("ghosts").checked;
    for (const [m, g] of modeGroups) {
      g.visible = m === k || ghosts;
      g.traverse((o) => { for (const mt of [].concat(o.material || [])) {
        if (mt.userData.opacity === undefined) mt.userData.opacity = mt.opacity, mt.userData.transparent = mt.transparent;
        const own = m === k; mt.opacity = own ? mt.userData.opacity : 0.15 * mt.userData.opacity;
        mt.transparent = own ? mt.userData.transparent : true; mt.depthWrite = own && !mt.userData.transparent; } });
    }
    legend(scene.items.filter((it) => it.mode === undefined || it.mode === k));
    const info = (scene.info || []).filter((l) => !/^mode \d+/.test(l) || l.startsWith("mode " + (k + 1) + ":") || l.startsWith("mode " + (k + 1) + " "));
    setInfo(info); status.mode = k; render();
  }
  if (modes.length) {
    $("modes-row").hidden = false;
    for (const m of modes) { const o = document.createElement("option"); o.value = m.index; o.textContent = m.label; $("modes").appendChild(o); }
    $("modes").addEventListener("change", () => showMode(Number($("modes").value)));
    $("ghosts").addEventListener("change", () => showMode(modeShown));
  }

  const robot = scene.robot;
  let q = robot ? robot.q.slice() : null;
  const unitOf = (i) => robot.kinds[i] === "prismatic" ? 1 : 180 / Math.PI;
  const fmtQ = (i, v) => (v * unitOf(i)).toFixed(2) + (robot.kinds[i] === "prismatic" ? " " + (scene.length_unit || "") : "°");
  function limitsOf(i) {   // the slider's interval (model units): the joint limits, else a turn / the scale
    const rev = robot.kinds[i] !== "prismatic";
    return [robot.lower[i] ?? (rev ? -Math.PI : -S), robot.upper[i] ?? (rev ? Math.PI : S)];
  }
  if (robot && robot.live) {
    const panel = $("sliders");
    robot.kinds.forEach((kind, i) => {
      const [lo, hi] = limitsOf(i), k = unitOf(i);
      q[i] = Math.min(Math.max(q[i], lo), hi);   // a slider never leaves the limits
      const row = document.createElement("label"), name = document.createElement("span");
      const inp = document.createElement("input"), out = document.createElement("span");
      name.className = "jname"; name.textContent = robot.joint_names[i]; name.title = robot.joint_names[i];
      inp.type = "range"; inp.min = lo * k; inp.max = hi * k; inp.step = "any"; inp.value = q[i] * k;
      inp.id = "joint" + (i + 1); inp.title = robot.joint_names[i];
      out.className = "jval"; out.textContent = fmtQ(i, q[i]); out.title = out.textContent;
      inp.addEventListener("input", () => {
        q[i] = Math.min(Math.max(Number(inp.value) / k, lo), hi); out.textContent = fmtQ(i, q[i]);
        drawRobot(robot, q); render();
      });
      row.append(name, inp, out); panel.appendChild(row);
    });
  }

  function setQ(values) {   // exact joint values (IK answers): the sliders only display them
    q = values.slice();
    robot.kinds.forEach((kind, i) => {
      const el = $("joint" + (i + 1));
      el.value = q[i] * unitOf(i); el.nextSibling.textContent = fmtQ(i, q[i]);
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
    $("step-label").textContent = st.label || ("step " + k);
    setInfo((scene.info || []).concat(st.info || []));
    legend(scene.items.concat(st.items || []));
    drawPlot(); render();
  }
  const timeline = $("timeline"), play = $("play");
  let timer = null;
  function setupPlayer() {
    $("player").hidden = !steps.length;
    timeline.max = Math.max(steps.length - 1, 0);
  }
  if (steps.length || scene.live) {
    setupPlayer();   // live runs add steps later
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
  showStick.addEventListener("change", () => { if (robot) drawRobot(robot, q); render(); });

  // ---- the force against the cycles (control runs), the cursor on the shown cycle ------------
  function drawPlot() {
    const sr = scene.series;
    if (!sr || plotCanvas.hidden) return;
    const W = plotCanvas.clientWidth, H = plotCanvas.clientHeight, dpr = window.devicePixelRatio || 1;
    if (plotCanvas.width !== Math.round(W * dpr)) { plotCanvas.width = Math.round(W * dpr); plotCanvas.height = Math.round(H * dpr); }
    const g = plotCanvas.getContext("2d"); g.setTransform(dpr, 0, 0, dpr, 0, 0); g.clearRect(0, 0, W, H);
    const n = sr.cycle.length, L = 52, R = 110, T = 14, B = 30;
    const comp = [0, 1, 2].map((j) => sr.force.map((f) => f[j]));
    const all = [].concat(sr.magnitude, ...comp, [sr.target, -sr.target, 0]);
    let lo = Math.min(...all), hi = Math.max(...all); const pad = 0.06 * (hi - lo || 1); lo -= pad; hi += pad;
    const c0 = n ? sr.cycle[0] : 0, c1 = n ? sr.cycle[n - 1] : 1;
    const X = (c) => L + (W - L - R) * (c1 > c0 ? (c - c0) / (c1 - c0) : 0.5), Y = (v) => T + (H - T - B) * (hi - v) / (hi - lo);
    g.strokeStyle = "#999"; g.lineWidth = 1; g.strokeRect(L, T, W - L - R, H - T - B);
    g.fillStyle = "#333"; g.font = "11px sans-serif"; g.textAlign = "right"; g.textBaseline = "middle";
    const st = niceStep((hi - lo) / 5);
    for (let v = Math.ceil(lo / st) * st; v <= hi; v += st) {
      g.fillText(+v.toFixed(6) + "", L - 4, Y(v)); g.strokeStyle = "#eee"; g.beginPath(); g.moveTo(L, Y(v)); g.lineTo(W - R, Y(v)); g.stroke();
    }
    g.textAlign = "center"; g.textBaseline = "top";
    const cs = niceStep(Math.max((c1 - c0) / 8, 1));
    for (let c = Math.ceil(c0 / cs) * cs; c <= c1; c += cs) g.fillText(String(c), X(c), H - B + 4);
    g.fillText("cycle", (L + W - R) / 2, H - 14);
    g.save(); g.translate(12, (T + H - B) / 2); g.rotate(-Math.PI / 2); g.fillText("force (" + sr.unit + ")", 0, -6); g.restore();
    const lines = [["|F|", sr.magnitude, "#111111", 2], ["Fx", comp[0], "#d62728", 1], ["Fy", comp[1], "#2ca02c", 1], ["Fz", comp[2], "#1f77b4", 1]];
    g.setLineDash([5, 4]); g.strokeStyle = "#ff7f0e"; g.beginPath(); g.moveTo(L, Y(sr.target)); g.lineTo(W - R, Y(sr.target)); g.stroke(); g.setLineDash([]);
    for (const [, ys, col, w] of lines) {
      g.strokeStyle = col; g.lineWidth = w; g.beginPath();
      ys.forEach((v, k) => { if (k) g.lineTo(X(sr.cycle[k]), Y(v)); else g.moveTo(X(sr.cycle[k]), Y(v)); }); g.stroke();
    }
    g.textAlign = "left"; g.textBaseline = "middle";
    lines.concat([["target", null, "#ff7f0e", 1]]).forEach(([name, , col], k) => {
      g.fillStyle = col; g.fillRect(W - R + 10, T + 8 + 16 * k, 14, 3); g.fillStyle = "#333"; g.fillText(name, W - R + 30, T + 9 + 16 * k);
    });
    if (n) {   // the cursor: the cycle shown in the 3D view
      const k = Math.min(status.step, n - 1), x = X(sr.cycle[k]);
      g.strokeStyle = "#7f00ff"; g.lineWidth = 1.5; g.beginPath(); g.moveTo(x, T); g.lineTo(x, H - B); g.stroke();
      const right = x < (L + W - R) / 2;
      g.fillStyle = "#7f00ff"; g.textAlign = right ? "left" : "right"; g.textBaseline = "top";
      g.fillText("cycle " + sr.cycle[k], x + (right ? 4 : -4), T + 4);
      status.cursor = { cycle: sr.cycle[k], x: x };
    }
  }
  plotCanvas.addEventListener("click", (e) => {   // click a cycle: the slider and the view follow
    const sr = scene.series; if (!sr || !sr.cycle.length) return;
    const r = plotCanvas.getBoundingClientRect(), W = r.width, L = 52, R = 110;
    const c0 = sr.cycle[0], c1 = sr.cycle[sr.cycle.length - 1];
    const c = c0 + (c1 - c0) * (e.clientX - r.left - L) / (W - L - R);
    let best = 0; sr.cycle.forEach((x, k) => { if (Math.abs(x - c) < Math.abs(sr.cycle[best] - c)) best = k; });
    timeline.value = best; showStep(best);
  });

  // ---- IK request (served pages only): a target box and a draggable target gizmo -------------
  const ikPanel = $("ik");
  let gizmo = null, ikTo = null;
  if (robot && robot.live && location.protocol.startsWith("http") && scene.ik_url) {
    ikPanel.hidden = false;
    const targetBox = $("ik-target");
    const end0 = chainFrames(robot, q)[q.length];
    const showTarget = (t) => { targetBox.value = t.map((x) => x.toFixed(3)).join(","); };
    showTarget([end0[0][3], end0[1][3], end0[2][3]]);
    ikTo = async (t) => {    // ask the server for every solution putting the end origin at t
      showTarget(t);
      const res = await fetch(scene.ik_url, { method: "POST", headers: { "Content-Type": "application/json" },
        body: JSON.stringify({ q: q, target: t }) });
      const ans = await res.json();
      const out = $("ik-out"), pick = $("ik-pick");
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
    $("ik-go").addEventListener("click", () => {
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
  function frameBox(box) {   // the camera looks at box from the front-right, all of it in view
    const c = box.getCenter(new THREE.Vector3()), r = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);
    const vfov = camera.fov * Math.PI / 180, hfov = 2 * Math.atan(Math.tan(vfov / 2) * camera.aspect);
    let d = 1.08 * r / Math.sin(Math.min(vfov, hfov) / 2);
    const dir = new THREE.Vector3(0.9, -1.4, 0.8).normalize(), corners = [];
    for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) corners.push(new THREE.Vector3(x, y, z));
    for (let it = 0; it < 4; it++) {   // closer while every corner stays in view (a sphere's fit is loose)
      camera.position.copy(c).addScaledVector(dir, d); camera.lookAt(c);
      camera.near = d / 100; camera.far = d * 100; camera.updateProjectionMatrix(); camera.updateMatrixWorld();
      const m = Math.max(...corners.map((p) => { const q = p.clone().project(camera); return Math.max(Math.abs(q.x), Math.abs(q.y)); }));
      if (!(m > 0) || m > 0.92) break;
      d *= 0.5 + 0.5 * m / 0.9;
    }
    camera.position.copy(c).addScaledVector(dir, d);
    camera.near = d / 100; camera.far = d * 100; camera.updateProjectionMatrix();
    controls.target.copy(c); controls.update(); render();
  }
  function fit() { frameBox(contentBox()); }
  function fitTool() {
    const f = scene.tool_focus, c = v3(f.point), h = new THREE.Vector3(f.radius, f.radius, f.radius).multiplyScalar(0.577);
    frameBox(new THREE.Box3(c.clone().sub(h), c.clone().add(h)));
  }
  $("fit").addEventListener("click", fit);
  if (scene.tool_focus) { $("fit-tool").hidden = false; $("fit-tool").addEventListener("click", fitTool); }
  function inFrame() {   // the drawn content's box, every corner inside the camera's view
    const b = contentBox(), P = [];
    for (const x of [b.min.x, b.max.x]) for (const y of [b.min.y, b.max.y]) for (const z of [b.min.z, b.max.z]) P.push(new THREE.Vector3(x, y, z));
    camera.updateMatrixWorld();
    const ndc = P.map((p) => p.clone().project(camera));
    const fl = floorInfo ? v3(floorInfo.centre).project(camera) : null;
    return { content: ndc.every((p) => Math.abs(p.x) <= 1 && Math.abs(p.y) <= 1 && p.z < 1),
      floor: !!fl && Math.abs(fl.x) <= 1 && Math.abs(fl.y) <= 1 && fl.z < 1 };
  }
  window.addEventListener("resize", () => {
    renderer.setSize(view.clientWidth, view.clientHeight);
    camera.aspect = view.clientWidth / view.clientHeight; camera.updateProjectionMatrix(); render(); drawPlot();
  });

  function publish() {
    const f = inFrame(); status.in_frame = f.content; status.floor_visible = f.floor;
    $("kinestat-status").textContent = JSON.stringify(status);
  }
  const api = { scene: scene, status: status, chainFrames: chainFrames, fit: fit, publish: publish,
    camera: camera, controls: controls };
  window.kinestatViewer = api;

  // "#step=N" in the address opens the animation at step N (links, screenshots)
  const wanted = /step=(\d+)/.exec(location.hash || "");
  const last = Math.max(steps.length - 1, 0);   // a live run opens on its latest cycle
  const first = wanted ? Math.min(Number(wanted[1]), last) : (scene.live ? last : 0);
  if (steps.length) { timeline.value = first; showStep(first); }
  else { if (robot) drawRobot(robot, q); setInfo(scene.info); legend(scene.items); }
  if (modes.length) showMode(modeShown);
  api.showStep = showStep; api.gizmo = gizmo; api.ikTo = ikTo; api.showMode = showMode;
  let pending = null;
  api.addStep = function (st) {   // live runs: a cycle as it is logged; drawn with the others
    steps.push(st);               // that arrived meanwhile, the newest shown (one render)
    if (scene.series && st.series) for (const key of ["cycle", "force", "magnitude"]) scene.series[key].push(st.series[key]);
    if (pending) { pending.push(st); return; }
    pending = [st];
    setTimeout(() => {
      const batch = pending; pending = null;
      setupPlayer();
      if (scene.info && scene.info.length) scene.info[0] = steps.length + " cycles, states " + runLength(steps.map((x) => x.state || "?"));
      const follow = Number(timeline.value) >= steps.length - 1 - batch.length;
      if (follow) { timeline.value = steps.length - 1; showStep(steps.length - 1); } else drawPlot();
      const now = Date.now();
      for (const x of batch) {
        x.shown_ms = now;
        if (status.live) status.live.received.push({ cycle: x.series ? x.series.cycle : null, shown_ms: now,
          got_ms: x.got_ms, read_ms: 1000 * x.read_at, made_ms: 1000 * x.drawn_at });
      }
      $("live-status").textContent = "live: " + (batch[batch.length - 1].label || ("cycle " + steps.length));
      publish();
    }, 0);
  };
  loadMeshes(robot).then(() => {
    buildGround(); fit(); render();
    status.ready = true;
    status.load_ms = performance.now();   // since navigation start: parse, build, first render
    status.webgl = renderer.getContext() ? true : false;
    status.live = scene.live ? { received: [], ended: !!scene.live.ended } : null;
    publish();
    if (scene.live && !scene.live.ended) listen();
  });
  function listen() {   // live runs: each cycle as the server reads it from the log
    const el = $("live-status"); el.hidden = false;
    el.textContent = "live: " + steps.length + " cycle(s) so far, waiting for the next";
    const es = new EventSource(scene.live.events + "?from=" + steps.length);
    es.onmessage = (e) => {
      const st = JSON.parse(e.data); st.got_ms = Date.now(); api.addStep(st);
    };
    es.addEventListener("end", (e) => {
      es.close();
      setTimeout(() => {   // after the last cycles are drawn
        status.live.ended = true;
        const rep = JSON.parse(e.data || "{}");
        el.textContent = "run ended" + (rep.stop_reason ? ": " + rep.stop_reason : "") + " (" + steps.length + " cycles)";
        publish();
      }, 0);
    });
    es.onopen = () => { status.live.open_ms = Date.now(); };
    es.onerror = () => { if (!status.live.ended) el.textContent = "live view: connection lost"; };
  }
})();
