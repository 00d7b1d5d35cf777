/* The liganimate viewer: a program's scenes as the runtime computed them.
 *
 * Reads the manifest (JSON) and the blob (base64) embedded in the page;
 * see runtime/view/_scene_data.py for their layout.  Frames are images as
 * `liganimate run` writes them: with SAMEFRAME k, frame f shows ticks
 * f*k .. f*k+k-1 together, each through the camera of its tick, over the
 * background of the frame's first tick.
 */
'use strict';
(function () {
  var TINT = [255, 120, 0];
  var el = function (id) { return document.getElementById(id); };
  var manifest = JSON.parse(el('lig-manifest').textContent);
  var bytes = LigGL.decodeBase64(el('lig-blob').textContent);
  var V = function (ref) { return LigGL.view(bytes, ref); };

  /* Options in the address: #size=640x480&scene=0&frame=12&look=thesis (the tests use them). */
  var opts = {};
  location.hash.replace(/^#/, '').split('&').forEach(function (kv) {
    var p = kv.split('=');
    if (p.length === 2) opts[p[0]] = p[1];
  });

  var canvas = el('view');
  var renderer;
  try {
    renderer = new LigGL.Renderer(canvas, opts.look === 'thesis' ? 'thesis' : 'modern');
  } catch (err) {
    el('info').textContent = 'Cannot draw: ' + err.message;
    return;
  }

  /* ---------------------------------------------------------------- scenes */
  var scenes = manifest.scenes.map(function (s) {
    var cams = V(s.cameras);
    var models = s.models.map(function (m) {
      var ticks = V(m.ticks);
      var rowOf = new Int32Array(s.length).fill(-1);
      for (var r = 0; r < ticks.length; r++) if (ticks[r] >= 0 && ticks[r] < s.length) rowOf[ticks[r]] = r;
      return {
        name: m.name, links: m.links, jointOfLink: m.jointOfLink, joints: m.joints,
        local: V(m.mesh.pos), link: V(m.mesh.link), rgb: V(m.mesh.rgb),
        rowOf: rowOf, matrices: V(m.matrices), angles: V(m.angles), L: m.links.length, J: m.joints.length,
        // Morphing segments (SHAPE LINK tracks): the rows that move, and their corners at each drawn tick.
        morphRows: m.morph ? V(m.morph.rows) : null, morphPos: m.morph ? V(m.morph.pos) : null,
        scratch: m.morph ? new Float32Array(V(m.mesh.pos)) : null
      };
    });
    var backgrounds = s.backgrounds.map(function (b) {
      var shown = new Uint8Array(s.length);
      var t = V(b.ticks);
      for (var i = 0; i < t.length; i++) if (t[i] >= 0 && t[i] < s.length) shown[t[i]] = 1;
      return { pos: V(b.pos), rgb: V(b.rgb), shown: shown };
    });
    var k = Math.max(1, s.sameframe);
    var most = 0;
    for (var t = 0; t < s.length; t++) {
      var n = 0;
      models.forEach(function (m) { if (m.rowOf[t] >= 0) n += m.link.length; });
      backgrounds.forEach(function (b) { if (b.shown[t]) n += b.rgb.length / 3; });
      most = Math.max(most, n);
    }
    return {
      id: s.id, length: s.length, k: k, images: Math.max(1, Math.ceil(s.length / k)), cams: cams,
      bounds: s.bounds, framing: s.framing, models: models, backgrounds: backgrounds, capacity: most * k
    };
  });

  /* ----------------------------------------------------------------- state */
  var state = { scene: 0, image: 0, playing: false, fps: 24, userCam: null, hover: null, pinned: null };
  var frame = { pos: new Float32Array(0), col: new Uint8Array(0), ranges: [], spans: [] };

  function sceneCamera(s, tick) {
    // A scene without VIEW, in the modern look: framed as `liganimate run` frames it.
    if (s.framing && renderer.look === 'modern') {
      return { eye: s.framing.eye.slice(), target: s.framing.target.slice(), k: s.framing.k };
    }
    var c = s.cams, i = Math.min(tick, c.length / 4 - 1) * 4;
    // A scene of no ticks has no camera: LIG's default VIEW.
    if (i < 0) return { eye: [0, 0, 10], target: [0, 0, 0], k: 1 };
    var eye = [c[i], c[i + 1], c[i + 2]];
    var d = Math.sqrt(eye[0] * eye[0] + eye[1] * eye[1] + eye[2] * eye[2]);
    return { eye: eye, target: [0, 0, 0], k: c[i + 3] / d };
  }

  function tickRange(s, image) {
    var t0 = image * s.k;
    return [t0, Math.min(s.length, t0 + s.k) - 1];
  }

  /* A model's triangles in their links' coordinates at one drawn tick: its own, or, where a
   * motion morphs segments, with the morphed rows' corners of that tick written in. */
  function shapeAt(m, row) {
    if (!m.morphRows) return m.local;
    var R = m.morphRows.length, local = m.scratch, pos = m.morphPos;
    for (var q = 0; q < R; q++) {
      var dst = m.morphRows[q] * 9, from = (row * R + q) * 9;
      for (var c = 0; c < 9; c++) local[dst + c] = pos[from + c];
    }
    return local;
  }

  function build() {
    var s = scenes[state.scene];
    var need = s.capacity * 9 + 9;
    if (frame.pos.length < need) { frame.pos = new Float32Array(need); frame.col = new Uint8Array(need); }
    var pos = frame.pos, col = frame.col, o = 0, oc = 0;
    var ranges = [], spans = [], objects = [];
    var tr = tickRange(s, state.image);
    var mark = state.pinned || state.hover;
    var add = function (first, cam) {
      var count = o / 3 - first;
      var last = ranges[ranges.length - 1];
      if (last && last.cam === cam && last.first + last.count === first) last.count += count;
      else ranges.push({ first: first, count: count, cam: cam });
    };
    var cam0 = state.userCam || sceneCamera(s, tr[0]);
    s.backgrounds.forEach(function (b) {
      if (!b.shown[tr[0]]) return;
      var first = o / 3;
      pos.set(b.pos, o); o += b.pos.length;
      oc = LigGL.colours(col, oc, b.rgb, null, -1, TINT);
      objects.push({ first: first, count: o / 3 - first });
      add(first, cam0);
    });
    for (var t = tr[0]; t <= tr[1]; t++) {
      var cam = state.userCam || (t === tr[0] ? cam0 : sceneCamera(s, t));
      for (var mi = 0; mi < s.models.length; mi++) {
        var m = s.models[mi], row = m.rowOf[t];
        if (row < 0) continue;
        var first = o / 3;
        o = LigGL.transform(pos, o, shapeAt(m, row), m.link, m.matrices, row * m.L * 12);
        var tint = mark && mark.model === mi && mark.tick === t ? mark.link : -1;
        oc = LigGL.colours(col, oc, m.rgb, m.link, tint, TINT);
        spans.push({ first: first, count: o / 3 - first, model: mi, tick: t, row: row, cam: cam });
        objects.push({ first: first, count: o / 3 - first });
        add(first, cam);
      }
    }
    frame.ranges = ranges;
    frame.spans = spans;
    frame.objects = objects;  // each casts or receives the contact shadow as one object
    frame.used = o;
  }

  function draw() {
    build();
    renderer.draw({ pos: frame.pos.subarray(0, frame.used), col: frame.col.subarray(0, frame.used),
      ranges: frame.ranges, objects: frame.objects }, scenes[state.scene].bounds);
    showFrame();
    showInfo();
  }

  /* -------------------------------------------------------------- readouts */
  function fmt(x) { return (Math.round(x * 100) / 100).toFixed(2); }
  function showFrame() {
    var s = scenes[state.scene], tr = tickRange(s, state.image);
    el('frame').textContent = 'frame ' + state.image + ' / ' + (s.images - 1);
    el('tick').textContent = tr[1] < tr[0] ? 'no ticks' : tr[0] === tr[1] ? 'tick ' + tr[0] :
      'ticks ' + tr[0] + '\u2013' + tr[1];
    el('scrub').value = String(state.image);
  }

  function showInfo() {
    var box = el('info');
    var mark = state.pinned || state.hover;
    if (!mark) { box.textContent = 'Hover over or click a segment to see its joint.'; return; }
    var s = scenes[state.scene], m = s.models[mark.model];
    var j = m.jointOfLink[mark.link];
    var lines = [m.name + ': segment ' + m.links[mark.link] + (state.pinned ? ' (pinned; click again to let go)' : '')];
    if (j < 0) {
      lines.push('the main link: no joint moves it (tick ' + mark.tick + ')');
    } else {
      var a = m.angles, b = (mark.row * m.J + j) * 3, e = m.joints[j].ext;
      var unit = m.joints[j].slide ? '' : '\u00b0';  // a slide's values are a displacement
      lines.push('joint ' + m.joints[j].id + (m.joints[j].slide ? ' (slide)' : '') + ' at tick ' + mark.tick +
        ': X ' + fmt(a[b]) + unit + '  Y ' + fmt(a[b + 1]) + unit + '  Z ' + fmt(a[b + 2]) + unit);
      lines.push('extremes: X (' + e[0][0] + ', ' + e[0][1] + ')  Y (' + e[1][0] + ', ' + e[1][1] +
        ')  Z (' + e[2][0] + ', ' + e[2][1] + ')');
    }
    box.textContent = lines.join('\n');
  }

  /* The segment under canvas pixel (px, py) of the content box, or null. */
  function pickAt(px, py) {
    var best = null, bestT = Infinity;
    for (var i = 0; i < frame.spans.length; i++) {
      var sp = frame.spans[i];
      var tri = LigGL.pick(px, py, canvas.clientWidth, canvas.clientHeight, sp.cam, frame.pos, sp.first, sp.count);
      if (tri < 0) continue;
      // Nearest along the ray: compare by the triangle's centre depth.
      var b = LigGL.basis(sp.cam), v = (sp.first + tri * 3) * 3, p = frame.pos;
      var depth = ((p[v] + p[v + 3] + p[v + 6]) / 3 - sp.cam.eye[0]) * b.fwd[0] +
        ((p[v + 1] + p[v + 4] + p[v + 7]) / 3 - sp.cam.eye[1]) * b.fwd[1] +
        ((p[v + 2] + p[v + 5] + p[v + 8]) / 3 - sp.cam.eye[2]) * b.fwd[2];
      if (depth <= bestT) {
        bestT = depth;
        var m = scenes[state.scene].models[sp.model];
        best = { model: sp.model, tick: sp.tick, row: sp.row, link: m.link[tri] };
      }
    }
    return best;
  }

  function same(a, b) {
    return a === b || (a && b && a.model === b.model && a.tick === b.tick && a.link === b.link);
  }

  /* --------------------------------------------------------------- sizing */
  var fixed = null;
  function layout() {
    var dpr = window.devicePixelRatio || 1;
    var w, h;
    if (fixed) { w = fixed[0]; h = fixed[1]; dpr = 1; } else {
      // The largest 4:3 picture that fits, like `liganimate run`'s default 640x480:
      // VIEW WIDTH spans the picture's width, so the aspect decides what is seen.
      var box = el('stage').getBoundingClientRect();
      w = Math.max(64, Math.floor(Math.min(box.width, box.height * 4 / 3)));
      h = Math.max(48, Math.floor(w * 3 / 4));
    }
    canvas.style.width = w + 'px';
    canvas.style.height = h + 'px';
    canvas.width = Math.round(w * dpr);
    canvas.height = Math.round(h * dpr);
  }

  /* -------------------------------------------------------------- controls */
  function setScene(i) {
    state.scene = Math.max(0, Math.min(scenes.length - 1, i | 0));
    state.image = 0; state.userCam = null; state.hover = null; state.pinned = null;
    var s = scenes[state.scene];
    el('scrub').max = String(s.images - 1);
    el('sceneSel').value = String(state.scene);
    draw();
  }
  function setFrame(f) {
    var s = scenes[state.scene];
    state.image = Math.max(0, Math.min(s.images - 1, f | 0));
    if (state.pinned && state.pinned.tick !== undefined) {
      // A pinned segment follows its model to the new frame's first tick.
      var t = tickRange(s, state.image)[0], m = s.models[state.pinned.model];
      state.pinned = m.rowOf[t] >= 0 ? { model: state.pinned.model, tick: t, row: m.rowOf[t], link: state.pinned.link } : null;
    }
    state.hover = null;
    draw();
  }
  function setPlaying(on) {
    state.playing = on;
    el('play').textContent = on ? 'Pause' : 'Play';
    if (on) { last = performance.now(); requestAnimationFrame(tick); }
  }
  var last = 0, carry = 0;
  function tick(now) {
    if (!state.playing) return;
    carry += (now - last) * state.fps / 1000;
    last = now;
    if (carry >= 1) {
      var s = scenes[state.scene], step = Math.floor(carry);
      carry -= step;
      setFrame((state.image + step) % s.images);
    }
    requestAnimationFrame(tick);
  }

  var sel = el('sceneSel');
  scenes.forEach(function (s, i) {
    var opt = document.createElement('option');
    opt.value = String(i);
    opt.textContent = 'scene ' + s.id + ' (' + s.length + ' ticks)';
    sel.appendChild(opt);
  });
  sel.addEventListener('change', function () { setScene(+sel.value); });
  el('play').addEventListener('click', function () { setPlaying(!state.playing); });
  el('scrub').addEventListener('input', function () { setFrame(+el('scrub').value); });
  el('fps').addEventListener('change', function () { state.fps = Math.max(1, +el('fps').value || 24); });
  el('reset').addEventListener('click', function () { state.userCam = null; draw(); });

  var drag = null;
  canvas.addEventListener('contextmenu', function (e) { e.preventDefault(); });
  canvas.addEventListener('pointerdown', function (e) {
    drag = { x: e.clientX, y: e.clientY, moved: false, pan: e.button === 2 || e.shiftKey };
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener('pointermove', function (e) {
    var r = canvas.getBoundingClientRect();
    var px = e.clientX - r.left - canvas.clientLeft, py = e.clientY - r.top - canvas.clientTop;
    if (drag) {
      var dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      if (!drag.moved && Math.abs(dx) + Math.abs(dy) < 3) return;
      drag.moved = true; drag.x = e.clientX; drag.y = e.clientY;
      if (!state.userCam) {
        var s = scenes[state.scene], c = sceneCamera(s, tickRange(s, state.image)[0]);
        state.userCam = { eye: c.eye.slice(), target: c.target.slice(), k: c.k };
      }
      if (drag.pan) LigGL.pan(state.userCam, dx, dy, canvas.clientWidth);
      else LigGL.orbit(state.userCam, dx * 0.01, dy * 0.01);
      draw();
      return;
    }
    var hit = pickAt(px, py);
    if (!same(hit, state.hover)) { state.hover = hit; draw(); }
  });
  canvas.addEventListener('pointerup', function (e) {
    if (drag && !drag.moved) {
      var r = canvas.getBoundingClientRect();
      var hit = pickAt(e.clientX - r.left - canvas.clientLeft, e.clientY - r.top - canvas.clientTop);
      state.pinned = hit && !same(hit, state.pinned) ? hit : null;
      draw();
    }
    drag = null;
  });
  canvas.addEventListener('pointerleave', function () { if (state.hover) { state.hover = null; draw(); } });
  canvas.addEventListener('wheel', function (e) {
    e.preventDefault();
    if (!state.userCam) {
      var s = scenes[state.scene], c = sceneCamera(s, tickRange(s, state.image)[0]);
      state.userCam = { eye: c.eye.slice(), target: c.target.slice(), k: c.k };
    }
    LigGL.zoom(state.userCam, Math.exp(e.deltaY * 0.001));
    draw();
  }, { passive: false });
  document.addEventListener('keydown', function (e) {
    if (e.target && e.target.tagName === 'INPUT' && e.target.type !== 'range') return;
    if (e.key === ' ') { e.preventDefault(); setPlaying(!state.playing); } else if (e.key === 'ArrowRight') {
      setFrame(state.image + 1);
    } else if (e.key === 'ArrowLeft') setFrame(state.image - 1);
  });
  window.addEventListener('resize', function () { layout(); draw(); });
  // A notebook's <iframe srcdoc> can run this script before the frame has its size, and
  // no resize event follows when the size arrives: the stage's own size is what to follow.
  if (window.ResizeObserver) {
    new ResizeObserver(function () { if (!fixed) { layout(); draw(); } }).observe(el('stage'));
  }

  if (/^\d+x\d+$/.test(opts.size || '')) fixed = opts.size.split('x').map(Number);
  layout();
  setScene(+(opts.scene || 0));
  if (opts.frame) setFrame(+opts.frame);

  window.ligViewer = {
    scenes: function () { return scenes.map(function (s) { return s.id; }); },
    frames: function () { return scenes[state.scene].images; },
    setScene: setScene, setFrame: setFrame,
    frame: function () { return state.image; },
    play: function (on) { setPlaying(on !== false); },
    hoverAt: function (x, y) { state.hover = pickAt(x, y); draw(); return el('info').textContent; },
    /* What view --watch keeps across a reload: the scene, the frame and the camera. */
    view: function () { return { scene: scenes[state.scene].id, image: state.image, cam: state.userCam }; },
    restore: function (v) {
      var i = scenes.map(function (s) { return s.id; }).indexOf(v.scene);
      if (i < 0) return;
      setScene(i);
      setFrame(v.image);
      state.userCam = v.cam || null;
      draw();
    },
    camera: function () { return state.userCam; },
    /* The camera the current frame starts from before any orbit: VIEW's, or run's default framing. */
    sceneCamera: function () { var s = scenes[state.scene]; return sceneCamera(s, tickRange(s, state.image)[0]); },
    ready: performance.now()
  };
})();
