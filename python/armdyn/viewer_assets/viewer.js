// armdyn's 3-D viewer: draws the scene that armdyn.viewer wrote as JSON into
// the scene script element. Runs after three.js (inlined before it as `THREE`).
// Link poses come precomputed per frame (x, y, z, qx, qy, qz, qw per link): no
// kinematics here. Reports what it loaded on <body data-status data-links data-frames
// data-meshes data-floor> (tests read it) and in the title.
(function () {
  "use strict";
  const S = JSON.parse(document.getElementById("armdyn-scene").textContent);
  const body = document.body;
  const nL = S.links.length, nF = S.times.length;
  const view = document.getElementById("armdyn-view");

  function report(status) {
    body.dataset.status = status;
    body.dataset.links = String(nL);
    body.dataset.frames = String(nF);
    body.dataset.meshes = String(S.meshes.length);
  }

  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (err) {
    view.textContent = "WebGL is not available in this browser: " + err.message;
    report("error: no WebGL");
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0xffffff, 1);
  view.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8d8d8d, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 2.0);
  sun.position.set(1, -2, 3);
  scene.add(sun);
  // a floor grid in the base's xy plane, for depth (grid lines every 0.25 of the arm's size)
  const grid = new THREE.GridHelper(3 * S.size, 12, 0xc4ccd5, 0xe1e6eb);
  grid.rotateX(Math.PI / 2);
  scene.add(grid);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
  camera.up.set(0, 0, 1);

  const size = S.size;
  const grey = new THREE.MeshStandardMaterial({ color: 0x9aa3ad, metalness: 0.1, roughness: 0.6 });
  const dark = new THREE.MeshStandardMaterial({ color: 0x3b4148, metalness: 0.1, roughness: 0.7 });
  const axisColour = { revolute: 0xe8871e, prismatic: 0x8250df };
  const material = (rgba) =>
    rgba ? new THREE.MeshStandardMaterial({ color: new THREE.Color(rgba[0], rgba[1], rgba[2]),
      opacity: rgba[3], transparent: rgba[3] < 1, metalness: 0.1, roughness: 0.6 }) : grey;

  function decode(b64, Type) {
    const bin = atob(b64), bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return new Type(bytes.buffer);
  }
  const geometries = S.meshes.map((m) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute("position", new THREE.BufferAttribute(decode(m.v, Float32Array), 3));
    g.setIndex(new THREE.BufferAttribute(decode(m.t, Uint32Array), 1));
    const flat = g.toNonIndexed();  // faceted normals: CAD meshes have sharp edges
    flat.computeVertexNormals();
    return flat;
  });

  function place(obj, pose) {
    obj.position.set(pose[0], pose[1], pose[2]);
    obj.quaternion.set(pose[3], pose[4], pose[5], pose[6]);
  }

  // one group per link frame, moved every frame
  const links = S.links.map(() => { const g = new THREE.Group(); scene.add(g); return g; });
  for (const v of S.visuals) {
    let geo;
    if (v.shape === "box") geo = new THREE.BoxGeometry(v.size[0], v.size[1], v.size[2]);
    else if (v.shape === "sphere") geo = new THREE.SphereGeometry(v.radius, 24, 16);
    else if (v.shape === "cylinder") geo = new THREE.CylinderGeometry(v.radius, v.radius, v.length, 32).rotateX(Math.PI / 2);
    else geo = geometries[v.mesh];
    const mesh = new THREE.Mesh(geo, material(v.rgba));
    place(mesh, v.pose);
    if (v.scale) mesh.scale.set(v.scale[0], v.scale[1], v.scale[2]);
    links[v.link].add(mesh);
  }
  // joints: short cylinders along their axes at the child frame's origin
  for (const j of S.joints) {
    const geo = new THREE.CylinderGeometry(0.045 * size, 0.045 * size, 0.12 * size, 24);
    const c = new THREE.Mesh(geo, new THREE.MeshStandardMaterial({ color: axisColour[j.type] || 0x888888 }));
    c.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), new THREE.Vector3(...j.axis).normalize());
    links[j.link].add(c);
  }
  for (const m of S.coms) {
    const s = new THREE.Mesh(new THREE.SphereGeometry(m.r, 20, 14), dark);
    s.position.set(m.com[0], m.com[1], m.com[2]);
    links[m.link].add(s);
  }
  if (S.axes) for (const g of links) g.add(new THREE.AxesHelper(0.1 * size));
  // capsules between joint origins: a unit cylinder + two spheres, stretched every frame
  const capsules = S.segments.map(([a, b]) => {
    const r = 0.025 * size;
    const group = new THREE.Group();
    const tube = new THREE.Mesh(new THREE.CylinderGeometry(r, r, 1, 20), grey);
    const ends = [0, 1].map(() => new THREE.Mesh(new THREE.SphereGeometry(r, 16, 12), grey));
    group.add(tube, ...ends);
    scene.add(group);
    return { a, b, tube, ends };
  });
  const Y = new THREE.Vector3(0, 1, 0);

  function show(k) {
    const base = k * nL * 7;
    for (let i = 0; i < nL; i++) {
      place(links[i], S.poses.slice(base + 7 * i, base + 7 * i + 7));
    }
    for (const c of capsules) {
      const pa = links[c.a].position, pb = links[c.b].position;
      const d = new THREE.Vector3().subVectors(pb, pa), len = d.length();
      c.tube.visible = len > 1e-9;
      c.tube.position.copy(pa).addScaledVector(d, 0.5);
      c.tube.scale.set(1, Math.max(len, 1e-9), 1);
      if (len > 1e-9) c.tube.quaternion.setFromUnitVectors(Y, d.divideScalar(len));
      c.ends[0].position.copy(pa);
      c.ends[1].position.copy(pb);
    }
  }

  // camera on a sphere around the arm: drag turns, wheel zooms
  const centre = new THREE.Vector3(...S.centre);
  let azimuth = -Math.PI / 3, elevation = 0.45, distance = 2.1 * size, zoom = 1;
  // what the first frame draws (meshes included, not only the joint origins): the view is
  // fitted to it, and the floor put under it when it reaches below the base (a legged
  // robot's feet stand on the floor instead of hanging through it)
  show(0);
  const box = new THREE.Box3();
  for (const g of links) box.expandByObject(g);
  for (const c of capsules) box.expandByObject(c.tube.parent);
  if (!box.isEmpty()) {
    box.getCenter(centre);
    grid.position.z = Math.min(0, box.min.z);
  }
  body.dataset.floor = String(grid.position.z);
  // the least distance at which every corner of the box is inside the view, with a margin
  function fit(aspect) {
    if (box.isEmpty()) return 2.1 * size;
    const ty = Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2), tx = ty * aspect;
    const back = new THREE.Vector3(Math.cos(elevation) * Math.cos(azimuth),
      Math.cos(elevation) * Math.sin(azimuth), Math.sin(elevation));
    const right = new THREE.Vector3(0, 0, 1).cross(back).normalize(), up = new THREE.Vector3().crossVectors(back, right);
    let d = 0;
    for (let i = 0; i < 8; i++) {
      const p = new THREE.Vector3(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y,
        i & 4 ? box.max.z : box.min.z).sub(centre);
      d = Math.max(d, p.dot(back) + Math.abs(p.dot(right)) / tx, p.dot(back) + Math.abs(p.dot(up)) / ty);
    }
    return 1.1 * d;
  }
  function aim() {
    camera.position.set(
      centre.x + distance * Math.cos(elevation) * Math.cos(azimuth),
      centre.y + distance * Math.cos(elevation) * Math.sin(azimuth),
      centre.z + distance * Math.sin(elevation));
    camera.lookAt(centre);
  }
  let drag = null;
  view.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; view.setPointerCapture(e.pointerId); });
  view.addEventListener("pointerup", () => { drag = null; });
  view.addEventListener("pointermove", (e) => {
    if (!drag) return;
    azimuth -= (e.clientX - drag[0]) * 0.01;
    elevation = Math.max(-1.5, Math.min(1.5, elevation + (e.clientY - drag[1]) * 0.01));
    drag = [e.clientX, e.clientY];
    draw();
  });
  view.addEventListener("wheel", (e) => { e.preventDefault(); zoom *= Math.exp(e.deltaY * 0.001); draw(); },
    { passive: false });

  function draw() {
    const w = view.clientWidth || 640, h = view.clientHeight || 480;
    renderer.setSize(w, h, false);
    renderer.domElement.style.width = "100%";
    renderer.domElement.style.height = "100%";
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    distance = zoom * fit(camera.aspect);
    aim();
    renderer.render(scene, camera);
  }
  window.addEventListener("resize", draw);

  // playback: real time, from the frames' own times
  const slider = document.getElementById("armdyn-slider");
  const play = document.getElementById("armdyn-play");
  const loop = document.getElementById("armdyn-loop");
  const clock = document.getElementById("armdyn-time");
  let frame = 0, playing = false, t0 = 0, last = 0, token = 0;
  // the next tick on the next animation frame, or after 40 ms if no frame comes first (a
  // headless or throttled page may paint no frames): whichever fires first runs it
  function schedule() {
    const id = ++token;
    requestAnimationFrame((now) => { if (id === token) tick(now); });
    setTimeout(() => { if (id === token) tick(performance.now()); }, 40);
  }
  function go(k) {
    frame = k;
    show(k);
    if (slider) slider.value = String(k);
    if (clock) clock.textContent = "t = " + S.times[k].toFixed(3) + " s";
    body.dataset.frame = String(k);
    draw();
  }
  function tick(now) {
    if (!playing) return;
    const t = S.times[0] + (now - t0) / 1000, end = S.times[nF - 1];
    if (t > end) {
      if (loop && loop.checked) { t0 = now; go(0); }
      else { go(nF - 1); playing = false; play.textContent = "Play"; return; }
    } else {
      let k = frame > 0 && S.times[frame] <= t ? frame : 0;
      while (k + 1 < nF && S.times[k + 1] <= t) k++;
      if (k !== last) go(k);
      last = k;
    }
    schedule();
  }
  if (play) {
    play.addEventListener("click", () => {
      playing = !playing;
      play.textContent = playing ? "Pause" : "Play";
      if (playing) {
        if (frame === nF - 1) go(0);
        t0 = performance.now() - (S.times[frame] - S.times[0]) * 1000;
        schedule();
      }
    });
    slider.addEventListener("input", () => { go(Number(slider.value)); t0 = performance.now() - (S.times[frame] - S.times[0]) * 1000; });
  }
  go(0);
  if (play && location.hash === "#play") play.click();  // a link (or a test) that starts playing
  document.title = S.name + " (3-D: " + nL + " links, " + nF + " frames)";
  report("ready");
})();
