// spinviz's page: each model of a scene in a 3-D view of its own, turnable, on the video's clock.
// Everything the page shows from outside (titles, captions, numbers) is set as text
// (textContent), never parsed as HTML.  The glTF travels in the page as base64 and is read
// with three.js's GLTFLoader from memory: nothing is fetched.  Until the 3-D views are drawn
// each shows its poster (inline SVG of the opening frame, in the markup).
(function () {
  'use strict';
  const D = JSON.parse(document.getElementById('spinviz-data').textContent);
  const $ = (id) => document.getElementById(id);
  const say = (text) => { $('status').textContent = text; };
  const n = D.panels;
  const slider = $('slider');
  const lastTime = (D.frames - 1) / D.fps;        // the MP4's clock: frame f at f / fps seconds
  let frame = 0;
  let setFrameHook = null;

  function showTexts(f) {
    $('time').textContent = D.time[f];
    $('notes').textContent = D.notes_table[D.notes_index[f]].join(' ');
    for (let k = 0; k < n; k++) $('read-' + k).textContent = D.readouts[k][f].join('\n');
    document.body.dataset.frame = String(f);
  }

  function setFrame(f) {
    frame = Math.max(0, Math.min(D.frames - 1, f | 0));
    slider.value = String(frame);
    showTexts(frame);
    if (setFrameHook) setFrameHook(frame);
  }

  slider.addEventListener('input', () => { stop(); setFrame(parseInt(slider.value, 10)); });

  // #frame=N opens the page at the video's frame N (as if the slider had been set there);
  // &view=AZ,EL (degrees, as the scene's azimuth_deg and elevation_deg) turns the view
  let turnHook = null;
  function fromFragment() {
    const m = /^#frame=(\d{1,7})(?:&view=(-?\d{1,3}(?:\.\d+)?),(-?\d{1,2}(?:\.\d+)?))?$/.exec(window.location.hash);
    if (!m) return;
    slider.value = String(Math.min(parseInt(m[1], 10), D.frames - 1));
    slider.dispatchEvent(new Event('input'));
    if (m[2] !== undefined && turnHook) turnHook(parseFloat(m[2]), Math.max(-89, Math.min(89, parseFloat(m[3]))));
  }
  window.addEventListener('hashchange', fromFragment);

  let playing = false;
  function stop() { playing = false; $('play').textContent = 'Play'; }
  $('play').addEventListener('click', () => {
    playing = !playing;
    $('play').textContent = playing ? 'Pause' : 'Play';
    if (playing && frame >= D.frames - 1) setFrame(0);
  });

  // full screen: the whole page but the footer, where the browser allows it
  const app = $('app');
  const full = $('full');
  if (document.fullscreenEnabled && app.requestFullscreen) {
    full.hidden = false;
    full.addEventListener('click', () => {
      if (document.fullscreenElement) document.exitFullscreen();
      else app.requestFullscreen().catch(() => {});
    });
    document.addEventListener('fullscreenchange', () => {
      full.textContent = document.fullscreenElement ? 'Exit full screen' : 'Full screen';
    });
  }
  showTexts(0);

  // --- WebGL ---------------------------------------------------------------------------------
  function hasWebGL() {
    try {
      const c = document.createElement('canvas');
      return !!(window.WebGLRenderingContext && (c.getContext('webgl2') || c.getContext('webgl')));
    } catch (e) {
      return false;
    }
  }
  function noGL() {
    document.body.classList.add('nogl');
    say(D.no_webgl);
    fromFragment();
  }
  if (!hasWebGL()) {
    noGL();
    return;
  }
  // the model is read after the posters have been painted
  window.requestAnimationFrame(() => window.setTimeout(start, 0));

  function start() {
    const raw = atob(document.getElementById('spinviz-glb').textContent.trim());
    const bytes = new Uint8Array(raw.length);
    for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
    new THREE.GLTFLoader().parse(bytes.buffer, '', ready, (err) => say('The model could not be read: ' + String(err && err.message)));
  }

  function ready(gltf) {
    const renderers = [];
    try {
      for (let k = 0; k < n; k++) renderers.push(new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true }));
    } catch (e) {
      noGL();
      return;
    }
    const views = [], labelBoxes = [];
    renderers.forEach((r, k) => {
      r.setPixelRatio(window.devicePixelRatio || 1);
      const canvas = r.domElement;
      canvas.id = 'canvas-' + k;
      canvas.setAttribute('role', 'img');
      canvas.setAttribute('aria-labelledby', 'alt');
      views.push($('view-' + k));
      labelBoxes.push($('labels-' + k));
      views[k].prepend(canvas);
    });

    const scene = new THREE.Scene();
    scene.background = new THREE.Color(D.background);
    scene.add(gltf.scene);
    // the file's lights are Blender's (lux); each view here is lit by lights that follow its camera
    const fileLights = [];
    gltf.scene.traverse((o) => { if (o.isLight) fileLights.push(o); });
    fileLights.forEach((o) => o.parent.remove(o));
    const models = [], bodies = [], worlds = [], arrows = [];
    gltf.scene.traverse((o) => {
      const u = o.userData;
      if (u.role === 'model') models[u.index] = o;
      if (u.role === 'body') bodies[u.index] = o;
      if (u.role === 'world') worlds[u.index] = o;
      if (u.role === 'arrow') arrows.push(o);
    });
    models.forEach((m, k) => m.traverse((o) => o.layers.set(k + 1)));   // each view draws its own model only
    const ambient = new THREE.AmbientLight(0xffffff, 0.9);
    const sun = new THREE.DirectionalLight(0xffffff, 2.0);
    ambient.layers.enableAll();
    sun.layers.enableAll();
    scene.add(ambient, sun, sun.target);

    // one camera that the pointer turns about the origin; each view sees its model from the same
    // direction relative to that model (its node's turn about the vertical included)
    const master = new THREE.PerspectiveCamera(30, 1, 0.05, 400);
    master.position.set(D.view[0], D.view[1], D.view[2]).multiplyScalar(D.distance);
    const controls = renderers.map((r) => {
      const c = new THREE.OrbitControls(master, r.domElement);
      c.enablePan = false;
      c.minDistance = 0.4 * D.distance;
      c.maxDistance = 8 * D.distance;
      c.update();
      return c;
    });
    turnHook = (azDeg, elDeg) => {
      const az = azDeg * Math.PI / 180, el = elDeg * Math.PI / 180, r = master.position.length();
      // spinviz's (x, y, z) is glTF's (x, -z, y): the world node turns z up into y up
      master.position.set(Math.cos(el) * Math.cos(az), Math.sin(el), -Math.cos(el) * Math.sin(az)).multiplyScalar(r);
      controls.forEach((c) => c.update());
    };
    scene.updateMatrixWorld(true);
    const centers = models.map((m) => m.getWorldPosition(new THREE.Vector3()));
    const turns = models.map((m) => m.quaternion.clone());
    const cams = models.map((m, k) => {
      const c = new THREE.PerspectiveCamera(30, 1, 0.05, 400);
      c.layers.set(k + 1);
      return c;
    });

    // labels: the arrows' symbols at their tips, the axes' names past their ends
    const labels = [];
    function label(k, text, cls) {
      const el = document.createElement('span');
      el.className = 'lab ' + cls;
      el.textContent = text;
      labelBoxes[k].append(el);
      return el;
    }
    arrows.forEach((a) => {
      const key = a.userData.key, k = a.userData.index;
      if (D.labels[key] === undefined) return;
      const head = a.children[1];
      labels.push({ k: k, el: label(k, D.labels[key], 'lab-' + key),
                    tip: () => head.localToWorld(new THREE.Vector3(a.userData.head_length, 0, 0)),
                    base: () => a.getWorldPosition(new THREE.Vector3()) });
    });
    if (D.axes) {
      for (let k = 0; k < n; k++) {
        [['x', [1, 0, 0]], ['y', [0, 1, 0]], ['z', [0, 0, 1]]].forEach(([name, e]) => {
          const end = new THREE.Vector3(...e).multiplyScalar(D.axis_length);
          labels.push({ k: k, el: label(k, name, 'axis'), tip: () => worlds[k].localToWorld(end.clone()),
                        base: () => worlds[k].getWorldPosition(new THREE.Vector3()) });
        });
      }
    }

    const clip = gltf.animations[0];
    const mixer = new THREE.AnimationMixer(gltf.scene);
    const action = mixer.clipAction(clip);
    action.setLoop(THREE.LoopOnce, 1);
    action.clampWhenFinished = true;
    action.play();
    action.paused = true;                      // the page drives the clock
    const keyTimes = clip.tracks[0].times;     // the keyframes' own (float32) times
    const keyOfFrame = new Map();
    D.key_frames.forEach((f, m) => { if (f >= 0) keyOfFrame.set(f, m); });
    let t = 0;

    function pose(k) {
      const q = bodies[k].quaternion;          // body -> spinviz world (its parent turns z up into y up)
      return [q.w, q.x, q.y, q.z];
    }
    window.pose = pose;                        // scalar first (w, x, y, z), as spinviz
    window.spinviz = { pose: pose, setFrame: setFrame, time: () => t };

    function setTime(tt) {
      t = tt;
      action.time = tt;
      mixer.update(0);
      for (let k = 0; k < n; k++) if (bodies[k]) $('panel-' + k).dataset.pose = JSON.stringify(pose(k));
      document.body.dataset.time = String(t);
    }
    setFrameHook = (f) => {
      const m = keyOfFrame.get(f);
      setTime(m !== undefined ? keyTimes[m] : f / D.fps);
    };

    const size = new THREE.Vector2();
    function draw() {
      for (let k = 0; k < n; k++) {
        const w = views[k].clientWidth, h = views[k].clientHeight;
        if (!w || !h) continue;
        const r = renderers[k];
        r.getSize(size);
        if (size.x !== w || size.y !== h) r.setSize(w, h, false);
        // the square |x|, |y| <= extent of the image plane fills the view's shorter side, as the poster's viewBox
        const a = w / h;
        const c = cams[k];
        c.fov = 2 * Math.atan(a >= 1 ? D.extent : D.extent / a) * 180 / Math.PI;
        c.aspect = a;
        c.updateProjectionMatrix();
        c.position.copy(master.position).applyQuaternion(turns[k]).add(centers[k]);
        c.quaternion.copy(turns[k]).multiply(master.quaternion);
        c.updateMatrixWorld();
        sun.position.copy(c.localToWorld(new THREE.Vector3(-2, 3, 0)));
        sun.target.position.copy(centers[k]);
        sun.target.updateMatrixWorld();
        r.render(scene, c);
        // each label just past its arrow's tip or its axis's end; an axis name that would sit on an
        // arrow's label moves to the side of its axis
        const placed = [];
        labels.forEach((l) => {
          if (l.k !== k) return;
          const tip = l.tip().project(c), base = l.base().project(c);
          let dx = (tip.x - base.x) * w, dy = (base.y - tip.y) * h;
          const len = Math.hypot(dx, dy) || 1;
          dx /= len; dy /= len;
          let x = 0.5 * (tip.x + 1) * w + 12 * dx, y = 0.5 * (1 - tip.y) * h + 12 * dy;
          if (placed.some(([px, py]) => Math.hypot(px - x, py - y) < 18)) { x += 16 * Math.abs(dy) + 4; y -= 16 * dx; }
          x = Math.min(w - 10, Math.max(10, x));
          y = Math.min(h - 10, Math.max(10, y));
          placed.push([x, y]);
          l.el.style.left = x.toFixed(1) + 'px';
          l.el.style.top = y.toFixed(1) + 'px';
        });
      }
    }

    let last = null;
    function loop(now) {
      if (playing) {
        const dt = last === null ? 0 : (now - last) / 1000;
        let tt = t + dt;
        if (tt > lastTime) tt -= lastTime;
        const f = Math.round(tt * D.fps);
        if (f !== frame) { frame = f; slider.value = String(f); showTexts(f); }
        setTime(tt);
      }
      last = now;
      draw();
      window.requestAnimationFrame(loop);
    }
    setFrame(frame);
    fromFragment();
    draw();
    say(D.how);
    document.body.classList.add('ready');
    window.requestAnimationFrame(loop);
  }
})();
