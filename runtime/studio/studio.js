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
  function addView(canvas, index) {
    var v = { canvas: canvas, index: index, renderer: new LigGL.Renderer(canvas),
      pos: new Float32Array(mesh.local.length), col: new Uint8Array(mesh.local.length) };
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

  function paint(v) {
    if (!mats) return;
    LigGL.transform(v.pos, 0, mesh.local, mesh.link, mats, v.index * L * 12);
    var col = v.col, o = 0, frozen = state.frozen;
    for (var t = 0; t < mesh.link.length; t++) {
      var l = mesh.link[t], tint = null;
      var r = mesh.rgb[3 * t], gg = mesh.rgb[3 * t + 1], b = mesh.rgb[3 * t + 2];
      if (hover.view === v.index && hover.link === l) tint = HOVER;
      else if (manifest.jointOfLink[l] >= 0 && frozen[manifest.jointOfLink[l]]) tint = FROZEN;
      if (tint) { r = (r + tint[0]) >> 1; gg = (gg + tint[1]) >> 1; b = (b + tint[2]) >> 1; }
      for (var k = 0; k < 3; k++) { col[o++] = r; col[o++] = gg; col[o++] = b; }
    }
    v.renderer.draw({ pos: v.pos, col: v.col, ranges: [{ first: 0, count: v.pos.length / 3, cam: cam }] },
      manifest.bounds);
  }
  function paintAll() { views.forEach(paint); }

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
    var tri = LigGL.pick(x, y, c.clientWidth, c.clientHeight, cam, v.pos, 0, v.pos.length / 3);
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
      if (v.index === 0) post({ action: 'freeze', link: link });
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
    /* A point of a view well inside a link (the link all round it), as
     * offsets from the canvas element's centre: where the tests click. */
    linkPoint: function (viewIndex, link) {
      var v = views[viewIndex], c = v.canvas, w = c.clientWidth, h = c.clientHeight;
      var b = LigGL.basis(cam), sx = 2 / cam.k, sy = sx * w / h, p = v.pos, spots = [];
      // Where the link's triangles' middles land on the canvas.
      for (var t = 0; t < mesh.link.length; t++) {
        if (mesh.link[t] !== link) continue;
        var d = [0, 1, 2].map(function (k) { return (p[t * 9 + k] + p[t * 9 + 3 + k] + p[t * 9 + 6 + k]) / 3 - cam.eye[k]; });
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
