/* The studio page: shows the Generator's poses and sends the user's choices.
 *
 * Every pose, candidate and decision comes from the server (the Generator
 * runs in Python); this script draws the segment matrices it receives and
 * posts {"action": ...} objects to /api/action.
 */
'use strict';
(function () {
  var HOVER = [255, 120, 0], FROZEN = [60, 110, 230];
  var el = function (id) { return document.getElementById(id); };
  var manifest = JSON.parse(el('lig-manifest').textContent);
  var bytes = LigGL.decodeBase64(el('lig-blob').textContent);
  var mesh = {
    local: LigGL.view(bytes, manifest.mesh.pos), link: LigGL.view(bytes, manifest.mesh.link),
    rgb: LigGL.view(bytes, manifest.mesh.rgb)
  };
  var L = manifest.links.length, N = manifest.population;
  var cam = { eye: manifest.camera.eye.slice(), target: manifest.camera.target.slice(), k: manifest.camera.k };
  var state = null, mats = null, pending = 0, hover = { view: -1, link: -1 };

  /* ----------------------------------------------------------------- views */
  var views = [];
  var NV = mesh.local.length / 3;  // the model's vertices; a floor's six follow them
  var cam0 = LigGL.basis(cam).distance;
  function addView(canvas, index) {
    var v = { canvas: canvas, index: index, renderer: new LigGL.Renderer(canvas),
      pos: new Float32Array(mesh.local.length + 18), col: new Uint8Array(mesh.local.length + 18), cam: cam,
      bounds: manifest.bounds };
    views.push(v);
    hook(v);
    return v;
  }
  try {
    addView(el('current'), 0);
    for (var i = 0; i < N; i++) {
      var box = document.createElement('div');
      box.className = 'cand';
      var c = document.createElement('canvas');
      c.width = 200; c.height = 200; c.id = 'cand' + i;
      var label = document.createElement('span');
      label.textContent = String(i + 1);
      box.appendChild(c); box.appendChild(label);
      el('grid').appendChild(box);
      addView(c, i + 1);
    }
  } catch (err) {
    status('Cannot draw: ' + err.message, true);
    return;
  }

  /* Each view frames its own pose (it fills the tile), seen from the shared direction and zoom. */
  function frame(v, pos) {
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (var i = 0; i < NV * 3; i += 3) {
      for (var k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], pos[i + k]); hi[k] = Math.max(hi[k], pos[i + k]); }
    }
    var c = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2];
    var r = Math.max(Math.sqrt((hi[0] - lo[0]) ** 2 + (hi[1] - lo[1]) ** 2 + (hi[2] - lo[2]) ** 2) / 2, 1e-9);
    var b = LigGL.basis(cam), z = b.distance / cam0, d = 3.2 * r * z;
    v.cam = { eye: [c[0] - b.fwd[0] * d, c[1] - b.fwd[1] * d, c[2] - b.fwd[2] * d], target: c, k: 2.15 * r / (3.2 * r) };
    v.bounds = [c[0], c[1], c[2], r * 3];
    return { lo: lo, hi: hi, c: c, r: r };
  }
  /* A floor under the lowest point of the pose: two triangles after the model's. */
  function floor(v, box) {
    var p = v.pos, o = NV * 3, y = box.lo[1], s = box.r * 1.2;
    var x0 = box.c[0] - s, x1 = box.c[0] + s, z0 = box.c[2] - s, z1 = box.c[2] + s;
    var quad = [x0, y, z0, x0, y, z1, x1, y, z1, x0, y, z0, x1, y, z1, x1, y, z0];
    for (var i = 0; i < 18; i++) { p[o + i] = quad[i]; v.col[o + i] = 200; }
  }
  function paint(v, matrices, block) {
    if (!mats) return;
    LigGL.transform(v.pos, 0, mesh.local, mesh.link, matrices || mats, (block === undefined ? v.index : block) * L * 12);
    var box = frame(v, v.pos), withFloor = el('floor').checked;
    if (withFloor) floor(v, box);
    var col = v.col, o = 0, frozen = state.frozen;
    for (var t = 0; t < mesh.link.length; t++) {
      var l = mesh.link[t], tint = null;
      var r = mesh.rgb[3 * t], gg = mesh.rgb[3 * t + 1], b = mesh.rgb[3 * t + 2];
      if (hover.view === v.index && hover.link === l) tint = HOVER;
      else if (manifest.jointOfLink[l] >= 0 && frozen[manifest.jointOfLink[l]]) tint = FROZEN;
      if (tint) { r = (r + tint[0]) >> 1; gg = (gg + tint[1]) >> 1; b = (b + tint[2]) >> 1; }
      for (var k = 0; k < 3; k++) { col[o++] = r; col[o++] = gg; col[o++] = b; }
    }
    // The figure casts the contact shadow, the floor receives it.
    var objects = [{ first: 0, count: NV }].concat(withFloor ? [{ first: NV, count: 6 }] : []);
    v.renderer.draw({ pos: v.pos, col: v.col, ranges: [{ first: 0, count: NV + (withFloor ? 6 : 0), cam: v.cam }],
      objects: objects }, v.bounds);
  }
  function paintAll() { views.forEach(function (v) { paint(v); }); }

  /* ------------------------------------------------------------- readouts */
  function status(text, bad) {
    var s = el('status');
    s.textContent = text;
    s.className = bad ? 'error' : '';
  }
  function fmt(x) { return (Math.round(x * 100) / 100).toFixed(2); }
  function describe(viewIndex, link) {
    var j = manifest.jointOfLink[link];
    var who = viewIndex === 0 ? 'current pose' : 'candidate ' + viewIndex;
    if (j < 0) return who + ': ' + manifest.links[link] + ', the main link (no joint moves it)';
    var a = state.angles[viewIndex][j], jt = manifest.joints[j];
    var text = who + ': ' + manifest.links[link] + ', joint ' + jt.id + ': X ' + fmt(a[0]) + '\u00b0  Y ' +
      fmt(a[1]) + '\u00b0  Z ' + fmt(a[2]) + '\u00b0';
    if (viewIndex > 0) {
      var lev = state.levels[viewIndex - 1][j];
      text += lev < 0 ? '  (as the current pose)' : '  (level ' + lev + ')  click to take it';
    } else {
      text += state.frozen[j] ? '  (frozen: click to let it mutate)' : '  (click to freeze it)';
    }
    return text;
  }
  function show(s) {
    state = s;
    var raw = LigGL.decodeBase64(s.matrices);
    mats = new Float32Array(raw.buffer, 0, raw.length / 4);
    el('generation').textContent = 'generation ' + s.generation;
    if (document.activeElement !== el('seed')) el('seed').value = String(s.seed);
    el('intensity').value = String(Math.max(1, Math.round(s.intensity * 100)));
    el('intensityValue').textContent = Math.round(s.intensity * 100) + '%';
    document.querySelectorAll('input[name=mode]').forEach(function (r) { r.checked = r.value === s.mode; });
    el('kept').textContent = s.kept + ' pose(s) kept' + (s.saved ? ', saved to ' + s.savePath : '');
    el('undo').disabled = !s.canUndo;
    if (s.message) status(s.message);
    paintAll();
    showEditor();
    showStrip();
    if (s.play) play(s.play);
  }

  /* --------------------------------------------------------- joint editor */
  var AXES = ['X', 'Y', 'Z'];
  (function () {
    var sel = el('joint');
    manifest.links.forEach(function (name, link) {
      if (manifest.jointOfLink[link] < 0) return;
      var o = document.createElement('option');
      o.value = String(link);
      o.textContent = name + ' (joint ' + manifest.joints[manifest.jointOfLink[link]].id + ')';
      sel.appendChild(o);
    });
    // Start on the first joint that can move at all (the HUMANOID's hips are locked).
    var free = Array.prototype.find.call(sel.options, function (o) {
      return manifest.joints[manifest.jointOfLink[+o.value]].ext.some(function (e) { return e[0] !== e[1]; });
    });
    if (free) sel.value = free.value;
  })();
  function editedJoint() { return manifest.jointOfLink[+el('joint').value]; }
  function showEditor() {
    var j = editedJoint(), ext = manifest.joints[j].ext, a = state.angles[0][j];
    AXES.forEach(function (ax, k) {
      var r = el('ang' + ax), n = el('num' + ax), locked = ext[k][0] === ext[k][1];
      [r, n].forEach(function (input) {
        input.min = String(ext[k][0]); input.max = String(ext[k][1]); input.disabled = locked;
        if (document.activeElement !== input) input.value = String(a[k]);
      });
    });
  }
  function sendAngles(from) {
    var angles = AXES.map(function (ax) { return +el(from + ax).value; });
    post({ action: 'set', link: +el('joint').value, angles: angles });
  }
  el('joint').addEventListener('change', function () { if (state) showEditor(); });
  AXES.forEach(function (ax) {
    el('ang' + ax).addEventListener('input', function () { el('num' + ax).value = el('ang' + ax).value; });
    el('ang' + ax).addEventListener('change', function () { sendAngles('ang'); });
    el('num' + ax).addEventListener('change', function () { sendAngles('num'); });
  });
  el('floor').addEventListener('change', paintAll);

  /* ------------------------------------------------------ kept poses strip */
  var thumbGL = null, selected = -1;
  function showStrip() {
    var strip = el('strip'), n = state.kept;
    var interp = el('interp');
    if (!interp.options.length) {
      state.interpolations.forEach(function (m) {
        var o = document.createElement('option'); o.value = m; o.textContent = m; interp.appendChild(o);
      });
    }
    interp.value = state.interpolation;
    while (strip.children.length > n) strip.removeChild(strip.lastChild);
    while (strip.children.length < n) strip.appendChild(thumb(strip.children.length));
    if (!n) return;
    var raw = LigGL.decodeBase64(state.keptMatrices), km = new Float32Array(raw.buffer, 0, raw.length / 4);
    if (!thumbGL) thumbGL = { canvas: el('thumbGL'), index: -2, renderer: new LigGL.Renderer(el('thumbGL')),
      pos: new Float32Array(mesh.local.length + 18), col: new Uint8Array(mesh.local.length + 18), cam: cam };
    for (var k = 0; k < n; k++) {
      paint(thumbGL, km, k);
      var box = strip.children[k], c2 = box.querySelector('canvas').getContext('2d');
      c2.drawImage(thumbGL.canvas, 0, 0);
      var f = box.querySelector('input');
      if (document.activeElement !== f) f.value = String(state.keptFrames[k]);
      f.disabled = k === 0;
      box.className = 'thumb' + (k === selected ? ' selected' : '');
    }
  }
  function thumb(k) {
    var box = document.createElement('div');
    box.className = 'thumb';
    box.id = 'kept' + k;
    var c = document.createElement('canvas');
    c.width = 110; c.height = 110;
    c.addEventListener('click', function () { selected = k; post({ action: 'recall', index: k }); });
    var f = document.createElement('input');
    f.type = 'number'; f.min = '0'; f.step = '1'; f.title = 'frame';
    f.addEventListener('change', function () { post({ action: 'frame', index: k, frame: Math.round(+f.value) }); });
    var row = document.createElement('div');
    [['\u25c0', 'earlier', function () { if (k > 0) post({ action: 'move', index: k, to: k - 1 }); }],
     ['\u25b6', 'later', function () { if (k + 1 < state.kept) post({ action: 'move', index: k, to: k + 1 }); }],
     ['\u2715', 'delete', function () { selected = -1; post({ action: 'delete', index: k }); }]].forEach(function (b) {
      var btn = document.createElement('button');
      btn.type = 'button'; btn.textContent = b[0]; btn.title = b[1]; btn.className = b[1];
      btn.addEventListener('click', b[2]);
      row.appendChild(btn);
    });
    box.appendChild(c); box.appendChild(f); box.appendChild(row);
    return box;
  }
  el('interp').addEventListener('change', function () { post({ action: 'interpolation', method: el('interp').value }); });
  el('play').addEventListener('click', function () { post({ action: 'play' }); });

  /* Play the kept poses as the saved motion does, in the current pose's view, 24 frames a second. */
  var playing = null;
  function play(p) {
    var raw = LigGL.decodeBase64(p.matrices), pm = new Float32Array(raw.buffer, 0, raw.length / 4);
    var v = views[0], start = performance.now(), shown = -1;
    playing = { frames: p.frames, shown: 0, done: false };
    function step(now) {
      var f = Math.min(p.frames - 1, Math.floor((now - start) * 24 / 1000));
      if (f !== shown) { paint(v, pm, f); shown = f; playing.shown = f; el('playing').textContent = 'frame ' + f; }
      if (f < p.frames - 1) requestAnimationFrame(step);
      else { playing.done = true; setTimeout(function () { paint(v); }, 500); }
    }
    requestAnimationFrame(step);
  }

  /* -------------------------------------------------------------- requests */
  function post(body) {
    pending++;
    document.body.dataset.busy = 'yes';
    return fetch('/api/action', { method: 'POST', headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify(body) })
      .then(function (r) {
        return r.json().then(function (j) {
          if (!r.ok) throw new Error(j.error || ('the server answered ' + r.status));
          show(j);
        });
      })
      .catch(function (err) { status(err.message, true); })
      .then(function () { if (--pending === 0) document.body.dataset.busy = 'no'; });
  }
  function settings() {
    var mode = document.querySelector('input[name=mode]:checked').value;
    return { intensity: Math.max(1, +el('intensity').value) / 100, mode: mode };
  }

  el('next').addEventListener('click', function () {
    var s = settings();
    post({ action: 'next', intensity: s.intensity, mode: s.mode });
  });
  el('intensity').addEventListener('input', function () { el('intensityValue').textContent = el('intensity').value + '%'; });
  el('intensity').addEventListener('change', function () { post(Object.assign({ action: 'settings' }, settings())); });
  document.querySelectorAll('input[name=mode]').forEach(function (r) {
    r.addEventListener('change', function () { post(Object.assign({ action: 'settings' }, settings())); });
  });
  el('setSeed').addEventListener('click', function () {
    var v = Number(el('seed').value);
    if (!Number.isInteger(v) || v < 0 || v > 4294967295) { status('the seed is a whole number from 0 to 4294967295', true); return; }
    post({ action: 'seed', seed: v });
  });
  el('undo').addEventListener('click', function () { post({ action: 'undo' }); });
  el('stand').addEventListener('click', function () { post({ action: 'stand' }); });
  el('keep').addEventListener('click', function () { post({ action: 'keep' }); });
  el('save').addEventListener('click', function () { post({ action: 'save' }); });

  /* ---------------------------------------------------------- pointer input */
  var drag = null;
  /* The link under a pointer, in the canvas's content box (inside its border). */
  function linkAt(v, e) {
    var c = v.canvas, r = c.getBoundingClientRect();
    return linkAtPixel(v, e.clientX - r.left - c.clientLeft, e.clientY - r.top - c.clientTop);
  }
  function linkAtPixel(v, x, y) {
    var c = v.canvas;
    var tri = LigGL.pick(x, y, c.clientWidth, c.clientHeight, v.cam, v.pos, 0, NV);
    return tri < 0 ? -1 : mesh.link[tri];
  }
  function hook(v) {
    var c = v.canvas;
    c.addEventListener('pointerdown', function (e) {
      drag = { x: e.clientX, y: e.clientY, moved: false, pan: e.button === 2 || e.shiftKey };
      c.setPointerCapture(e.pointerId);
    });
    c.addEventListener('contextmenu', function (e) { e.preventDefault(); });
    c.addEventListener('pointermove', function (e) {
      if (drag) {
        var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
        if (!drag.moved && Math.abs(dx) + Math.abs(dy) < 3) return;
        drag.moved = true; drag.x = e.clientX; drag.y = e.clientY;
        if (drag.pan) LigGL.pan(cam, dx, dy, c.getBoundingClientRect().width);
        else LigGL.orbit(cam, dx * 0.01, dy * 0.01);
        paintAll();
        return;
      }
      if (!state) return;
      var link = linkAt(v, e);
      if (link !== hover.link || v.index !== hover.view) {
        var old = hover.view;
        hover = { view: link < 0 ? -1 : v.index, link: link };
        if (old >= 0 && old !== v.index) paint(views[old]);
        paint(v);
        if (link >= 0) status(describe(v.index, link));
      }
    });
    c.addEventListener('pointerleave', function () {
      if (hover.view === v.index) { hover = { view: -1, link: -1 }; paint(v); }
    });
    c.addEventListener('pointerup', function (e) {
      var click = drag && !drag.moved;
      drag = null;
      if (!click || !state) return;
      var link = linkAt(v, e);
      if (link < 0) return;
      if (v.index === 0) {
        if (manifest.jointOfLink[link] >= 0) el('joint').value = String(link);
        post({ action: 'freeze', link: link });
      }
      else post({ action: 'take', candidate: v.index - 1, link: link });
    });
    c.addEventListener('wheel', function (e) {
      e.preventDefault();
      LigGL.zoom(cam, Math.exp(e.deltaY * 0.001));
      paintAll();
    }, { passive: false });
  }

  window.ligStudio = {
    state: function () { return state; },
    busy: function () { return pending > 0; },
    playing: function () { return playing; },
    /* A point of a view well inside a link (the link all round it), as
     * offsets from the canvas element's centre: where the tests click. */
    linkPoint: function (viewIndex, link) {
      var v = views[viewIndex], c = v.canvas, w = c.clientWidth, h = c.clientHeight;
      var vc = v.cam, b = LigGL.basis(vc), sx = 2 / vc.k, sy = sx * w / h, p = v.pos, spots = [];
      // Where the link's triangles' middles land on the canvas.
      for (var t = 0; t < mesh.link.length; t++) {
        if (mesh.link[t] !== link) continue;
        var d = [0, 1, 2].map(function (k) { return (p[t * 9 + k] + p[t * 9 + 3 + k] + p[t * 9 + 6 + k]) / 3 - vc.eye[k]; });
        var z = d[0] * b.fwd[0] + d[1] * b.fwd[1] + d[2] * b.fwd[2];
        if (z <= 0) continue;
        var xc = d[0] * b.right[0] + d[1] * b.right[1] + d[2] * b.right[2];
        var yc = d[0] * b.up[0] + d[1] * b.up[1] + d[2] * b.up[2];
        spots.push([Math.round((xc * sx / z + 1) * w / 2), Math.round((1 - yc * sy / z) * h / 2)]);
      }
      for (var m = 3; m >= 0; m--) {
        for (var i = 0; i < spots.length; i++) {
          var x = spots[i][0], y = spots[i][1];
          if (x < m || y < m || x >= w - m || y >= h - m) continue;
          if (linkAtPixel(v, x, y) === link && linkAtPixel(v, x - m, y) === link && linkAtPixel(v, x + m, y) === link &&
              linkAtPixel(v, x, y - m) === link && linkAtPixel(v, x, y + m) === link) {
            var r = c.getBoundingClientRect();
            return [x + c.clientLeft - r.width / 2, y + c.clientTop - r.height / 2];
          }
        }
      }
      return null;
    }
  };
  fetch('/api/state').then(function (r) { return r.json(); }).then(show)
    .catch(function (err) { status('Cannot reach the studio server: ' + err.message, true); });
})();
