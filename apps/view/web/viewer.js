// rtfact view: the page. It steers the camera (orbit/pan/zoom with mouse, wheel, touch,
// keys), shows the frames the server sends (acknowledging each), and edits the
// settings of the scene's domain, with a transfer-function editor for volumes.
'use strict';
(() => {
  const token = new URLSearchParams(location.search).get('token') || '';
  const canvas = document.getElementById('view');
  const ctx = canvas.getContext('2d');
  const statusEl = document.getElementById('status');
  const $ = (id) => document.getElementById(id);

  // Small vector helpers.
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
  const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const len = (a) => Math.sqrt(dot(a, a));
  const norm = (a) => mul(a, 1 / (len(a) || 1));
  // Rotation of v about unit axis k by angle t (Rodrigues).
  const rotate = (v, k, t) => {
    const c = Math.cos(t), s = Math.sin(t);
    return add(add(mul(v, c), mul(cross(k, v), s)), mul(k, dot(k, v) * (1 - c)));
  };

  const state = {
    ws: null, hello: null, camera: null, settings: null,
    expect: null,            // meta data of the binary message to come
    cameraSent: 0,           // time the last camera message went out, 0: answered by a frame
    cameraPending: null,     // newer camera waiting for the answer to the previous one
    frames: [], lastScreenshot: null, framesReceived: 0, lastFrame: null, transfer: null,
  };
  window.rtfactView = state;  // for tests and the curious

  function send(obj) {
    if (state.ws && state.ws.readyState === WebSocket.OPEN) state.ws.send(JSON.stringify(obj));
  }

  // Camera messages: at most one outstanding (the next goes when a frame answers or after
  // 200 ms), so that a fast drag does not cancel every pass before it finishes.
  function sendCamera(moving) {
    const c = state.camera;
    const msg = { type: 'camera', eye: c.eye, at: c.at, up: c.up, fov: c.fov, moving };
    if (moving && state.cameraSent && performance.now() - state.cameraSent < 200) {
      state.cameraPending = msg;
      return;
    }
    state.cameraPending = null;
    state.cameraSent = moving ? performance.now() : 0;
    send(msg);
    updateCamText();
  }
  function flushCamera() {
    state.cameraSent = 0;
    if (state.cameraPending) { const m = state.cameraPending; state.cameraPending = null; state.cameraSent = performance.now(); send(m); }
  }
  setInterval(() => { if (state.cameraPending && performance.now() - state.cameraSent >= 200) flushCamera(); }, 50);

  const fmt = (v) => v.map((x) => +x.toPrecision(6)).join(',');
  function updateCamText() {
    const c = state.camera;
    if (!c) return;
    $('camtext').value = `--eye ${fmt(c.eye)} --at ${fmt(c.at)} --up ${fmt(c.up)} --fov ${+c.fov.toPrecision(6)}` +
      (state.hello ? ` --size ${state.hello.width}x${state.hello.height}` : '');
  }

  // --- camera control ---------------------------------------------------------------
  function orbit(dx, dy) {
    const c = state.camera;
    let off = sub(c.eye, c.at);
    const up = norm(c.up);
    off = rotate(off, up, -dx * 0.01);
    const right = norm(cross(sub(c.at, c.eye), up));
    const tilted = rotate(off, right, -dy * 0.01);
    // Stop short of the poles (up parallel to the view).
    if (Math.abs(dot(norm(tilted), up)) < 0.995) off = tilted;
    c.eye = add(c.at, off);
  }
  function pan(dx, dy) {
    const c = state.camera;
    const view = sub(c.at, c.eye);
    const dist = len(view);
    const right = norm(cross(view, c.up));
    const up = norm(cross(right, view));
    const k = 2 * dist * Math.tan((c.fov * Math.PI) / 360) / (canvas.clientHeight || 1);
    const d = add(mul(right, -dx * k), mul(up, dy * k));
    c.eye = add(c.eye, d);
    c.at = add(c.at, d);
  }
  function zoom(f) {
    const c = state.camera;
    c.eye = add(c.at, mul(sub(c.eye, c.at), f));
  }

  let drag = null;
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => {
    if (!state.camera) return;
    canvas.setPointerCapture(e.pointerId);
    drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey };
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag || e.pointerType === 'touch') return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) pan(dx, dy); else orbit(dx, dy);
    sendCamera(true);
  });
  const endDrag = () => { if (drag) { drag = null; sendCamera(false); } };
  canvas.addEventListener('pointerup', endDrag);
  canvas.addEventListener('pointercancel', endDrag);

  let wheelTimer = 0;
  canvas.addEventListener('wheel', (e) => {
    if (!state.camera) return;
    e.preventDefault();
    zoom(Math.exp(Math.sign(e.deltaY) * Math.min(Math.abs(e.deltaY), 200) * 0.002));
    sendCamera(true);
    clearTimeout(wheelTimer);
    wheelTimer = setTimeout(() => sendCamera(false), 150);
  }, { passive: false });

  // Touch: one finger orbits, two pinch-zoom and pan.
  let touches = null;
  const touchInfo = (t) => {
    if (t.length === 1) return { n: 1, x: t[0].clientX, y: t[0].clientY };
    const x = (t[0].clientX + t[1].clientX) / 2, y = (t[0].clientY + t[1].clientY) / 2;
    return { n: 2, x, y, d: Math.hypot(t[0].clientX - t[1].clientX, t[0].clientY - t[1].clientY) };
  };
  canvas.addEventListener('touchstart', (e) => { e.preventDefault(); touches = touchInfo(e.touches); }, { passive: false });
  canvas.addEventListener('touchmove', (e) => {
    e.preventDefault();
    if (!touches || !state.camera) return;
    const t = touchInfo(e.touches);
    if (t.n !== touches.n) { touches = t; return; }
    if (t.n === 1) orbit(t.x - touches.x, t.y - touches.y);
    else { pan(t.x - touches.x, t.y - touches.y); if (touches.d > 0 && t.d > 0) zoom(touches.d / t.d); }
    touches = t;
    sendCamera(true);
  }, { passive: false });
  canvas.addEventListener('touchend', (e) => {
    touches = e.touches.length ? touchInfo(e.touches) : null;
    if (!touches) sendCamera(false);
  });

  document.addEventListener('keydown', (e) => {
    if (!state.camera || e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
    const k = e.key;
    if (k === 'ArrowLeft') orbit(-20, 0);
    else if (k === 'ArrowRight') orbit(20, 0);
    else if (k === 'ArrowUp') orbit(0, -20);
    else if (k === 'ArrowDown') orbit(0, 20);
    else if (k === '+' || k === '=') zoom(0.9);
    else if (k === '-') zoom(1 / 0.9);
    else if (k === 'f' || k === 'F') { send({ type: 'fit' }); return; }
    else if (k === 'r' || k === 'R') { send({ type: 'reset' }); return; }
    else return;
    e.preventDefault();
    sendCamera(false);
  });

  $('fit').onclick = () => send({ type: 'fit' });
  $('reset').onclick = () => send({ type: 'reset' });
  $('copy').onclick = () => {
    updateCamText();
    $('camtext').select();
    if (navigator.clipboard) navigator.clipboard.writeText($('camtext').value).catch(() => {});
  };
  $('shot').onclick = () => { statusEl.textContent = 'rendering screenshot…'; send({ type: 'screenshot' }); };

  // --- frames -----------------------------------------------------------------------
  let fpsCount = 0, fpsT0 = performance.now();
  async function showFrame(meta, blob) {
    try {
      const bmp = await createImageBitmap(blob);
      if (canvas.width !== meta.fullWidth || canvas.height !== meta.fullHeight) {
        canvas.width = meta.fullWidth; canvas.height = meta.fullHeight;
      }
      ctx.imageSmoothingEnabled = true;
      ctx.drawImage(bmp, 0, 0, canvas.width, canvas.height);
      bmp.close();
    } finally {
      send({ type: 'ack', frame: meta.id });
    }
    state.framesReceived++;
    state.lastFrame = meta;
    fpsCount++;
    const now = performance.now();
    if (now - fpsT0 > 1000) { $('s-fps').textContent = (fpsCount * 1000 / (now - fpsT0)).toFixed(1); fpsCount = 0; fpsT0 = now; }
    $('s-ms').textContent = meta.ms.toFixed(1);
    $('s-res').textContent = `${meta.width}×${meta.height}` + (meta.scale > 1 ? ` (1/${meta.scale})` : '');
    $('s-spp').textContent = meta.samples;
    $('s-mrays').textContent = meta.mrays.toFixed(1);
    statusEl.textContent = meta.moving ? 'preview' : meta.samples >= state.hello.maxSamples ? 'done' : 'refining…';
    flushCamera();
  }

  function onText(msg) {
    switch (msg.type) {
      case 'hello':
        state.hello = msg;
        state.camera = msg.camera;
        state.settings = msg.settings;
        canvas.width = msg.width; canvas.height = msg.height;
        $('source').textContent = `${msg.kind}: ${msg.source}`;
        buildSettings();
        updateCamText();
        break;
      case 'frame': case 'screenshot':
        state.expect = msg;
        break;
      case 'camera':
        state.camera = { eye: msg.eye, at: msg.at, up: msg.up, fov: msg.fov };
        updateCamText();
        break;
      case 'transfer':
        state.transfer = msg;
        tfEditor.load(msg);
        break;
      case 'error':
        statusEl.textContent = 'error: ' + msg.message;
        console.warn('rtfact view:', msg.message);
        break;
    }
  }

  function onBinary(blob) {
    const meta = state.expect;
    state.expect = null;
    if (!meta) return;
    if (meta.type === 'frame') showFrame(meta, blob);
    else if (meta.type === 'screenshot') {
      state.lastScreenshot = blob;
      const a = document.createElement('a');
      a.href = URL.createObjectURL(blob);
      a.download = 'rtfact-view.png';
      document.body.appendChild(a); a.click(); a.remove();
      setTimeout(() => URL.revokeObjectURL(a.href), 10000);
      statusEl.textContent = `screenshot ${meta.width}×${meta.height} saved`;
    }
  }

  function connect() {
    const ws = new WebSocket(`ws://${location.host}/ws?token=${encodeURIComponent(token)}`);
    ws.binaryType = 'blob';
    ws.onmessage = (e) => {
      if (typeof e.data === 'string') onText(JSON.parse(e.data));
      else onBinary(e.data);
    };
    ws.onopen = () => { statusEl.textContent = 'connected'; };
    ws.onclose = () => { statusEl.textContent = 'disconnected (reload to reconnect)'; };
    state.ws = ws;
  }

  // --- settings panels --------------------------------------------------------------
  function sendSettings(patch) {
    const domain = state.hello.kind === 'points' ? 'points' : state.hello.kind === 'volume' ? 'volume' : 'mesh';
    Object.assign(state.settings, patch);
    send({ type: 'settings', [domain]: patch });
  }
  function select(name, options, value, onchange) {
    const l = document.createElement('label');
    l.textContent = name;
    const s = document.createElement('select');
    s.name = name;
    for (const o of options) { const op = document.createElement('option'); op.value = op.textContent = o; s.appendChild(op); }
    s.value = value;
    s.onchange = () => onchange(s.value);
    l.appendChild(s);
    return l;
  }
  function range(name, min, max, step, value, onchange) {
    const l = document.createElement('label');
    l.textContent = name;
    const r = document.createElement('input');
    Object.assign(r, { type: 'range', min, max, step, value, name });
    const out = document.createElement('span');
    out.textContent = (+value).toFixed(2);
    r.oninput = () => { out.textContent = (+r.value).toFixed(2); };
    r.onchange = () => onchange(+r.value);
    l.append(r, out);
    return l;
  }
  function check(name, value, onchange) {
    const l = document.createElement('label');
    l.textContent = name;
    const c = document.createElement('input');
    Object.assign(c, { type: 'checkbox', checked: value, name });
    c.onchange = () => onchange(c.checked);
    l.appendChild(c);
    return l;
  }
  function buildSettings() {
    const box = $('settings');
    box.innerHTML = '<h2>Settings</h2>';
    const h = state.hello, s = h.settings, ch = h.choices;
    if (h.kind === 'points') {
      box.append(
        select('integrator', ch.integrator, s.integrator, (v) => sendSettings({ integrator: v })),
        select('color', ch.color, s.color, (v) => sendSettings({ color: v })),
        check('LoD', s.lod, (v) => sendSettings({ lod: v })),
        range('LoD quality', 0, 8, 0.1, s.lodQuality, (v) => sendSettings({ lodQuality: v })),
        range('radius factor', 0.2, 5, 0.05, s.radiusFactor, (v) => sendSettings({ radiusFactor: v })));
    } else if (h.kind === 'volume') {
      box.append(
        select('mode', ch.mode, s.mode, (v) => sendSettings({ mode: v })),
        select('TF preset', ['(default)', ...ch.tf], s.tf && ch.tf.includes(s.tf.name) ? s.tf.name : '(default)',
          (v) => sendSettings({ tf: v === '(default)' ? null : v, window: null, level: null })),
        range('step (voxels)', 0.1, 4, 0.05, s.step, (v) => sendSettings({ step: v })),
        check('pre-integrated', s.preintegrated, (v) => sendSettings({ preintegrated: v })));
      for (let a = 0; a < 3; ++a) {
        const ax = 'xyz'[a];
        box.append(
          range(`clip ${ax} low`, 0, 0.99, 0.01, s.clipLo[a], (v) => {
            const lo = state.settings.clipLo.slice(); lo[a] = Math.min(v, state.settings.clipHi[a] - 0.01);
            sendSettings({ clipLo: lo });
          }),
          range(`clip ${ax} high`, 0.01, 1, 0.01, s.clipHi[a], (v) => {
            const hi = state.settings.clipHi.slice(); hi[a] = Math.max(v, state.settings.clipLo[a] + 0.01);
            sendSettings({ clipHi: hi });
          }));
      }
      $('tf').hidden = false;
    } else if (h.kind === 'mesh') {
      box.append(
        select('integrator', ch.integrator, s.integrator, (v) => sendSettings({ integrator: v })),
        select('material', ch.material, s.material, (v) => sendSettings({ material: v })));
      let az = 0.8, el = 0.9;
      const light = () => sendSettings({ light: [-Math.cos(el) * Math.sin(az), -Math.sin(el), -Math.cos(el) * Math.cos(az)] });
      box.append(
        check('default light', s.light === null, (v) => (v ? sendSettings({ light: null }) : light())),
        range('light azimuth', -3.14, 3.14, 0.01, az, (v) => { az = v; light(); }),
        range('light elevation', 0.05, 1.5, 0.01, el, (v) => { el = v; light(); }));
    }
  }

  // --- transfer-function editor -----------------------------------------------------
  const tfEditor = (() => {
    const cv = $('tf-canvas'), g = cv.getContext('2d');
    const bar = $('tf-colors'), gb = bar.getContext('2d');
    const pick = $('tf-color-pick');
    let info = null, opacity = [], colors = [], win = [0, 1], dragIdx = -1, sendTimer = 0, maxA = 1;
    const toX = (x) => x * cv.width, toY = (a) => cv.height - 4 - (a / maxA) * (cv.height - 8);
    const fromX = (px) => Math.min(1, Math.max(0, px / cv.width));
    const fromY = (py) => Math.min(maxA, Math.max(0, ((cv.height - 4 - py) / (cv.height - 8)) * maxA));
    const hex = (c) => '#' + c.map((v) => Math.round(Math.min(1, Math.max(0, v)) * 255).toString(16).padStart(2, '0')).join('');

    function colorAt(x) {
      if (!colors.length) return [1, 1, 1];
      if (x <= colors[0][0]) return colors[0].slice(1);
      for (let i = 1; i < colors.length; ++i)
        if (x <= colors[i][0]) {
          const a = colors[i - 1], b = colors[i], t = (x - a[0]) / (b[0] - a[0] || 1);
          return [1, 2, 3].map((k) => a[k] + t * (b[k] - a[k]));
        }
      return colors[colors.length - 1].slice(1);
    }
    function draw() {
      g.clearRect(0, 0, cv.width, cv.height);
      if (info) {
        // Histogram over the window, log counts.
        const bins = info.bins, n = bins.length, w = (info.hi - info.lo) / n;
        const maxLog = Math.log1p(Math.max(...bins));
        g.fillStyle = '#555';
        for (let i = 0; i < n; ++i) {
          const v0 = info.lo + i * w, x0 = (v0 - win[0]) / (win[1] - win[0]), x1 = (v0 + w - win[0]) / (win[1] - win[0]);
          if (x1 < 0 || x0 > 1) continue;
          const hgt = (Math.log1p(bins[i]) / maxLog) * (cv.height - 8);
          g.fillRect(toX(x0), cv.height - 4 - hgt, Math.max(1, toX(x1) - toX(x0)), hgt);
        }
      }
      g.strokeStyle = '#fff'; g.lineWidth = 1.5; g.beginPath();
      opacity.forEach((p, i) => (i ? g.lineTo(toX(p[0]), toY(p[1])) : g.moveTo(toX(p[0]), toY(p[1]))));
      g.stroke();
      for (const p of opacity) {
        g.fillStyle = hex(colorAt(p[0]));
        g.beginPath(); g.arc(toX(p[0]), toY(p[1]), 5, 0, 2 * Math.PI); g.fill(); g.stroke();
      }
      for (let px = 0; px < bar.width; ++px) { gb.fillStyle = hex(colorAt(px / bar.width)); gb.fillRect(px, 0, 1, bar.height); }
      g.fillStyle = '#aaa'; g.font = '10px sans-serif';
      g.fillText(win[0].toPrecision(4), 2, 10);
      const t = win[1].toPrecision(4); g.fillText(t, cv.width - 2 - g.measureText(t).width, 10);
    }
    function load(msg) {
      info = msg;
      const tf = msg.tf;
      win = tf.space === 'data' ? [msg.lo, msg.hi] : msg.window;
      const nx = (x) => (tf.space === 'data' ? (x - win[0]) / (win[1] - win[0]) : x);
      opacity = tf.opacity.map((p) => [nx(p[0]), p[1]]);
      colors = tf.colors.map((c) => [nx(c[0]), c[1], c[2], c[3]]);
      maxA = Math.max(0.05, ...opacity.map((p) => p[1])) * 1.25;
      draw();
    }
    function commit() {
      clearTimeout(sendTimer);
      sendTimer = setTimeout(() => sendSettings({
        tf: { name: 'edited', space: 'normalized', colors, opacity },
        window: win[1] - win[0], level: (win[0] + win[1]) / 2,
      }), 60);
    }
    const pos = (e) => { const r = cv.getBoundingClientRect(); return [(e.clientX - r.left) * cv.width / r.width, (e.clientY - r.top) * cv.height / r.height]; };
    const hit = (x, y) => opacity.findIndex((p) => Math.hypot(toX(p[0]) - x, toY(p[1]) - y) < 8);
    cv.addEventListener('contextmenu', (e) => {
      e.preventDefault();
      const i = hit(...pos(e));
      if (i > 0 && i < opacity.length - 1) { opacity.splice(i, 1); draw(); commit(); }
    });
    cv.addEventListener('pointerdown', (e) => {
      if (e.button !== 0) return;
      dragIdx = hit(...pos(e));
      if (dragIdx >= 0) cv.setPointerCapture(e.pointerId);
    });
    cv.addEventListener('pointermove', (e) => {
      if (dragIdx < 0) return;
      const [x, y] = pos(e), p = opacity[dragIdx];
      // Ends stay at 0 and 1; inner points between their neighbours.
      if (dragIdx > 0 && dragIdx < opacity.length - 1)
        p[0] = Math.min(opacity[dragIdx + 1][0] - 1e-3, Math.max(opacity[dragIdx - 1][0] + 1e-3, fromX(x)));
      p[1] = fromY(y);
      draw(); commit();
    });
    cv.addEventListener('pointerup', () => { dragIdx = -1; });
    cv.addEventListener('dblclick', (e) => {
      const [x, y] = pos(e), nx = fromX(x);
      let i = opacity.findIndex((p) => p[0] > nx);
      if (i <= 0) return;
      opacity.splice(i, 0, [nx, fromY(y)]);
      draw(); commit();
    });
    let pickX = 0;
    bar.addEventListener('click', (e) => {
      const r = bar.getBoundingClientRect();
      pickX = Math.min(1, Math.max(0, (e.clientX - r.left) / r.width));
      pick.value = hex(colorAt(pickX));
      pick.click();
    });
    pick.addEventListener('input', () => {
      const v = pick.value, c = [1, 3, 5].map((k) => parseInt(v.substr(k, 2), 16) / 255);
      const i = colors.findIndex((p) => Math.abs(p[0] - pickX) < 0.02);
      if (i >= 0) colors[i] = [colors[i][0], ...c];
      else { colors.push([pickX, ...c]); colors.sort((a, b) => a[0] - b[0]); }
      draw(); commit();
    });
    // Opacity points in canvas pixels (for tests).
    const points = () => opacity.map((p) => [toX(p[0]), toY(p[1])]);
    return { load, draw, points };
  })();
  state.tfEditor = tfEditor;

  connect();
})();
