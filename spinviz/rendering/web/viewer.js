// spinviz's page: both models of a scene side by side, turnable, on the video's clock.
// Everything the page shows from outside (titles, captions, numbers) is set as text
// (textContent), never parsed as HTML.  The glTF travels in the page as base64 and is read
// with three.js's GLTFLoader from memory: nothing is fetched.
(function () {
  'use strict';
  const D = JSON.parse(document.getElementById('spinviz-data').textContent);
  const $ = (id) => document.getElementById(id);
  const say = (text) => { $('status').textContent = text; };
  const n = D.headings.length;
  const slider = $('slider');
  let frame = 0;
  let setFrameHook = null;

  // --- the texts ---------------------------------------------------------------------------
  $('title').textContent = D.title;
  $('scale').textContent = D.scale;
  $('stage').classList.add('n' + n);
  for (let k = 0; k < n; k++) {
    $('head-' + k).textContent = D.headings[k][0] + '  ' + D.headings[k][1];
    $('head-' + k).style.color = D.model_colors[k];
    $('sub-' + k).textContent = D.subtitles[k];
  }
  D.legend.forEach((item) => {
    const chip = document.createElement('span');
    chip.className = 'chip';
    chip.style.background = item.color;
    const name = document.createElement('span');
    name.textContent = item.symbol + ' ' + item.name;
    $('legend').append(chip, name);
  });
  D.ticks.forEach((tick) => {
    const mark = document.createElement('span');
    mark.className = 'tick';
    mark.style.left = (100 * tick[0]).toFixed(3) + '%';
    mark.textContent = tick[1];
    $('ticks').append(mark);
  });
  slider.max = String(D.frames - 1);

  function showTexts(f) {
    $('time').textContent = D.time[f];
    $('notes').textContent = D.notes_table[D.notes_index[f]].join(' · ');
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
  const NO_GL = 'This browser has no WebGL, so the crystals cannot be drawn here; the captions and the ' +
                'time slider still work, and the video shows the same motion.';
  if (!hasWebGL()) {
    document.body.classList.add('nogl');
    say(NO_GL);
    fromFragment();
    return;
  }

  const raw = atob(document.getElementById('spinviz-glb').textContent.trim());
  const bytes = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
  new THREE.GLTFLoader().parse(bytes.buffer, '', ready, (err) => say('The model could not be read: ' + String(err && err.message)));

  function ready(gltf) {
    let renderer;
    try {
      renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    } catch (e) {
      document.body.classList.add('nogl');
      say(NO_GL);
      return;
    }
    const stage = $('stage');
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setScissorTest(true);
    renderer.domElement.id = 'view';
    stage.prepend(renderer.domElement);

    const scene = new THREE.Scene();
    scene.background = new THREE.Color(D.background);
    scene.add(gltf.scene);
    const models = [], bodies = [];
    gltf.scene.traverse((o) => {
      if (o.userData.role === 'model') models[o.userData.index] = o;
      if (o.userData.role === 'body') bodies[o.userData.index] = o;
    });
    models.forEach((m, k) => m.traverse((o) => o.layers.set(k + 1)));   // each view draws its own model only
    const ambient = new THREE.AmbientLight(0xffffff, 0.9);
    const sun = new THREE.DirectionalLight(0xffffff, 2.0);
    ambient.layers.enableAll();
    sun.layers.enableAll();
    scene.add(ambient, sun, sun.target);

    // one camera that the mouse turns about the origin; each view copies it to its model
    const fov = D.yfov_deg;
    const master = new THREE.PerspectiveCamera(fov, 1, 0.05, 200);
    const dist = 1.75 / Math.tan(0.5 * fov * Math.PI / 180) * 1.3;
    master.position.set(D.view[0], D.view[1], D.view[2]).multiplyScalar(dist);
    const controls = new THREE.OrbitControls(master, renderer.domElement);
    controls.enablePan = false;
    controls.minDistance = 2;
    controls.maxDistance = 40;
    controls.update();
    turnHook = (azDeg, elDeg) => {
      const az = azDeg * Math.PI / 180, el = elDeg * Math.PI / 180, r = master.position.length();
      // spinviz's (x, y, z) is glTF's (x, -z, y): the world node turns z up into y up
      master.position.set(Math.cos(el) * Math.cos(az), Math.sin(el), -Math.cos(el) * Math.sin(az)).multiplyScalar(r);
      controls.update();
    };
    const centers = models.map((m) => m.getWorldPosition(new THREE.Vector3()));
    const cams = models.map((m, k) => {
      const c = new THREE.PerspectiveCamera(fov, 1, 0.05, 200);
      c.layers.set(k + 1);
      return c;
    });

    const labels = [];
    if (D.axes) {
      for (let k = 0; k < n; k++) {
        ['x', 'y', 'z'].forEach((name) => {
          const el = document.createElement('span');
          el.className = 'axis';
          el.textContent = name;
          $('labels').append(el);
          labels.push(el);
        });
      }
    }
    const axisEnds = [[1, 0, 0], [0, 0, -1], [0, 1, 0]].map((v) => new THREE.Vector3(...v).multiplyScalar(D.axis_length * 1.1));

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
      setTime(m !== undefined ? keyTimes[m] : f * D.duration / (D.frames - 1));
    };

    function draw() {
      const w = stage.clientWidth, h = stage.clientHeight;
      const size = renderer.getSize(new THREE.Vector2());
      if (size.x !== w || size.y !== h) renderer.setSize(w, h, false);
      const pw = w / n;
      let li = 0;
      for (let k = 0; k < n; k++) {
        const c = cams[k];
        c.aspect = pw / h;
        c.updateProjectionMatrix();
        c.position.copy(master.position).add(centers[k]);
        c.quaternion.copy(master.quaternion);
        c.updateMatrixWorld();
        sun.position.copy(c.localToWorld(new THREE.Vector3(-2, 3, 0)));
        sun.target.position.copy(centers[k]);
        sun.target.updateMatrixWorld();
        renderer.setViewport(k * pw, 0, pw, h);
        renderer.setScissor(k * pw, 0, pw, h);
        renderer.render(scene, c);
        if (D.axes) {
          axisEnds.forEach((e) => {
            const p = e.clone().add(centers[k]).project(c);
            labels[li].style.left = ((k + 0.5 * (p.x + 1)) * pw).toFixed(1) + 'px';
            labels[li].style.top = (0.5 * (1 - p.y) * h).toFixed(1) + 'px';
            li++;
          });
        }
      }
    }

    let last = null;
    function loop(now) {
      if (playing) {
        const dt = last === null ? 0 : (now - last) / 1000;
        let tt = t + dt;
        if (tt > D.duration) tt -= D.duration;
        const f = Math.round(tt / D.duration * (D.frames - 1));
        if (f !== frame) { frame = f; slider.value = String(f); showTexts(f); }
        setTime(tt);
      }
      last = now;
      draw();
      window.requestAnimationFrame(loop);
    }
    setFrame(frame);
    fromFragment();
    say('Drag to turn both crystals, scroll to zoom; the slider and Play run the video\'s clock.');
    document.body.classList.add('ready');
    window.requestAnimationFrame(loop);
  }
})();
