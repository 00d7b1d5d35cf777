/* LIG GL: draws what the liganimate runtime computed, shaded like its rasterizer.
 *
 * Triangles come in segment coordinates with one colour each (the
 * rasterizer's flat shading: LIGHTNESS 0..100 -> 0..255, times COLOUR).
 * A Renderer draws in one of the two looks of `liganimate run --look`
 * (docs/semantics-render.md, "Looks"): 'thesis', flat on white; or
 * 'modern' (the default), each face lit by the same key light and ambient
 * term as the rasterizer's modern look, outlines along silhouettes,
 * creases (normals over 50 degrees apart) and changes of colour, the
 * same grey background, edges smoothed by the browser's multisampling, and
 * the same soft contact shadow (shadow.js, computed from each picture's
 * pose);
 * segment matrices come from the runtime, one 3x4 row-major block per
 * segment.  This file only multiplies vertices by those matrices: it never
 * turns joint angles into transforms.
 *
 * The camera is LIG's: an eye looking at a target (the origin for VIEW),
 * +Y up (-Z when looking straight along Y), and a view width measured in
 * the plane through the target, so the picture matches the rasterizer's
 * pixel for pixel up to rounding.  Shared by the viewer and the studio.
 */
'use strict';
var LigGL = (function () {
  var VS = 'attribute vec3 p; attribute vec3 c; uniform mat4 mvp; varying vec3 vc;' +
    'void main() { vc = c; gl_Position = mvp * vec4(p, 1.0); }';
  var FS = 'precision highp float; varying vec3 vc; void main() { gl_FragColor = vec4(vc, 1.0); }';
  /* The contact shadow: a square on the ground whose texture (shadow.js) multiplies the colour under it. */
  var SHADOW_VS = 'attribute vec3 p; uniform mat4 mvp; uniform vec3 map; varying vec2 uv;' +
    'void main() { uv = vec2(0.5 - (p.x - map.x) * map.z, 0.5 + (p.z - map.y) * map.z);' +
    ' gl_Position = mvp * vec4(p, 1.0); }';
  var SHADOW_FS = 'precision mediump float; uniform sampler2D keep; varying vec2 uv;' +
    'void main() { gl_FragColor = vec4(texture2D(keep, uv).rrr, 1.0); }';
  var PARALLEL_SINE = 1e-9;

  function sub(a, b) { return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]; }
  function dot(a, b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  function cross(a, b) { return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]; }
  function norm(a) { return Math.sqrt(dot(a, a)); }
  function scale(a, k) { return [a[0] * k, a[1] * k, a[2] * k]; }

  /* The camera's right, up and forward unit vectors, as runtime/camera.py builds them. */
  function basis(cam) {
    var v = sub(cam.target, cam.eye);
    var d = norm(v);
    var fwd = scale(v, 1 / d);
    var hint = [0, 1, 0];
    if (norm(cross(fwd, hint)) < PARALLEL_SINE) hint = [0, 0, -1];
    var right = cross(fwd, hint);
    right = scale(right, 1 / norm(right));
    return { right: right, up: cross(right, fwd), fwd: fwd, distance: d };
  }

  /* Column-major model-view-projection matrix for a canvas of w x h pixels.
   * cam.k is the view width divided by the eye's distance to the target.
   * bounds = [cx, cy, cz, radius] of everything drawn (near and far planes). */
  function projection(cam, w, h, bounds) {
    var b = basis(cam);
    var sx = 2 / cam.k, sy = sx * w / h;
    var dc = dot(sub([bounds[0], bounds[1], bounds[2]], cam.eye), b.fwd);
    var r = bounds[3] * 1.05 + 1e-9;
    var far = Math.max(dc + r, 1e-6);
    var near = Math.max(dc - r, far * 1e-4);
    var r0 = b.right, u = b.up, f = b.fwd, e = cam.eye;
    // View: camera x = right, y = up, z = -forward (GL looks down -z).
    var V = [r0[0], u[0], -f[0], 0, r0[1], u[1], -f[1], 0, r0[2], u[2], -f[2], 0,
      -dot(r0, e), -dot(u, e), dot(f, e), 1];
    var A = -(far + near) / (far - near), B = -2 * far * near / (far - near);
    var P = [sx, 0, 0, 0, 0, sy, 0, 0, 0, 0, A, -1, 0, 0, B, 0];
    var M = new Float32Array(16);
    for (var col = 0; col < 4; col++) {
      for (var row = 0; row < 4; row++) {
        var s = 0;
        for (var k = 0; k < 4; k++) s += P[k * 4 + row] * V[col * 4 + k];
        M[col * 4 + row] = s;
      }
    }
    return { mvp: M, basis: b, sx: sx, sy: sy };
  }

  /* World positions of a mesh posed by segment matrices.
   * local: Float32Array (M*9) in segment coordinates; link: segment of each
   * triangle; mats: Float32Array holding L blocks of 12 from index m0. */
  function transform(out, o, local, link, mats, m0) {
    var n = link.length;
    for (var t = 0; t < n; t++) {
      var b = m0 + link[t] * 12;
      var a00 = mats[b], a01 = mats[b + 1], a02 = mats[b + 2], a03 = mats[b + 3];
      var a10 = mats[b + 4], a11 = mats[b + 5], a12 = mats[b + 6], a13 = mats[b + 7];
      var a20 = mats[b + 8], a21 = mats[b + 9], a22 = mats[b + 10], a23 = mats[b + 11];
      for (var v = 0; v < 3; v++) {
        var i = t * 9 + v * 3;
        var x = local[i], y = local[i + 1], z = local[i + 2];
        out[o++] = a00 * x + a01 * y + a02 * z + a03;
        out[o++] = a10 * x + a11 * y + a12 * z + a13;
        out[o++] = a20 * x + a21 * y + a22 * z + a23;
      }
    }
    return o;
  }

  /* Per-vertex colours: each triangle's colour (rgb holds three levels a
   * triangle, grey ones as three equal levels), or mixed with a tint where
   * tintLink (a segment index, -1 for none) matches the triangle's segment. */
  function colours(out, o, rgb, link, tintLink, tint) {
    var n = rgb.length / 3;
    for (var t = 0; t < n; t++) {
      var r = rgb[3 * t], gg = rgb[3 * t + 1], bb = rgb[3 * t + 2];
      if (link !== null && link[t] === tintLink) {
        r = (r + tint[0]) >> 1; gg = (gg + tint[1]) >> 1; bb = (bb + tint[2]) >> 1;
      }
      for (var v = 0; v < 3; v++) { out[o++] = r; out[o++] = gg; out[o++] = bb; }
    }
    return o;
  }

  /* The modern look's parameters: those of runtime/render/look.py's Look. */
  var MODERN = { light: [-0.3, 0.6, -0.75], ambient: 0.75, key: 0.4, crease: Math.cos(50 * Math.PI / 180),
    ink: 0.25, background: 244 / 255 };

  function Renderer(canvas, look) {
    this.look = look === 'thesis' ? 'thesis' : 'modern';
    var modern = this.look === 'modern';
    var gl = canvas.getContext('webgl', { antialias: modern, preserveDrawingBuffer: true, alpha: false });
    if (!gl) throw new Error('this browser has no WebGL, which the viewer needs');
    this.gl = gl;
    this.canvas = canvas;
    var prog = program(gl, VS, FS);
    this.prog = prog;
    this.aP = gl.getAttribLocation(prog, 'p');
    this.aC = gl.getAttribLocation(prog, 'c');
    this.uM = gl.getUniformLocation(prog, 'mvp');
    this.pos = gl.createBuffer();
    this.col = gl.createBuffer();
    this.linePos = gl.createBuffer();
    this.lineCol = gl.createBuffer();
    this.capacity = 0;
    if (modern) {
      var sp = this.shadowProg = program(gl, SHADOW_VS, SHADOW_FS);
      this.sP = gl.getAttribLocation(sp, 'p');
      this.sM = gl.getUniformLocation(sp, 'mvp');
      this.sMap = gl.getUniformLocation(sp, 'map');
      this.sKeep = gl.getUniformLocation(sp, 'keep');
      this.shadowQuad = gl.createBuffer();
      this.shadowTex = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, this.shadowTex);
      // The renderer looks up the texel a point falls in: nearest, no mipmaps.
      [[gl.TEXTURE_MIN_FILTER, gl.NEAREST], [gl.TEXTURE_MAG_FILTER, gl.NEAREST], [gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE],
        [gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE]].forEach(function (p) { gl.texParameteri(gl.TEXTURE_2D, p[0], p[1]); });
    }
  }

  /* A linked shader program, or an Error with the compiler's log. */
  function program(gl, vs, fs) {
    var prog = gl.createProgram();
    [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]].forEach(function (s) {
      var sh = gl.createShader(s[0]);
      gl.shaderSource(sh, s[1]);
      gl.compileShader(sh);
      if (!gl.getShaderParameter(sh, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(sh));
      gl.attachShader(prog, sh);
    });
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    return prog;
  }

  /* Lit colours (modern look): each triangle's colour times ambient + key * max(0, n . L),
   * n facing the eye, L the key light turned with the camera; at most white. */
  function lit(pos, col, first, count, cam, out) {
    var b = basis(cam), l = MODERN.light, ln = Math.sqrt(dot(l, l));
    var L = [0, 1, 2].map(function (k) { return (b.right[k] * l[0] + b.up[k] * l[1] + b.fwd[k] * l[2]) / ln; });
    var normals = new Float32Array(count);  // (count / 3 triangles) x 3
    for (var v = first; v < first + count; v += 3) {
      var i = v * 3;
      var ax = pos[i + 3] - pos[i], ay = pos[i + 4] - pos[i + 1], az = pos[i + 5] - pos[i + 2];
      var bx = pos[i + 6] - pos[i], by = pos[i + 7] - pos[i + 1], bz = pos[i + 8] - pos[i + 2];
      var n = [ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx];
      var len = Math.sqrt(dot(n, n)) || Infinity;
      var toEye = [cam.eye[0] - pos[i], cam.eye[1] - pos[i + 1], cam.eye[2] - pos[i + 2]];
      var s = (dot(n, toEye) < 0 ? -1 : 1) / len;
      n = [n[0] * s, n[1] * s, n[2] * s];
      var t = (v - first) / 3;
      normals[3 * t] = n[0]; normals[3 * t + 1] = n[1]; normals[3 * t + 2] = n[2];
      var f = MODERN.ambient + MODERN.key * Math.max(0, dot(n, L));
      for (var c = 0; c < 9; c++) out[i + c] = Math.min(255, Math.floor(col[i + c] * f + 0.5));
    }
    return normals;
  }

  /* Outline segments (modern look): edges of a silhouette (one face towards the eye, one away),
   * of the surface's border, of a crease, or between two colours. */
  function outlines(pos, col, first, count, cam, normals, lines, lineCol) {
    var edges = new Map();
    function key(i) { return pos[i] + ',' + pos[i + 1] + ',' + pos[i + 2]; }
    for (var v = first; v < first + count; v += 3) {
      for (var e = 0; e < 3; e++) {
        var a = (v + e) * 3, b = (v + (e + 1) % 3) * 3, ka = key(a), kb = key(b);
        var k = ka < kb ? ka + '|' + kb : kb + '|' + ka;
        var seen = edges.get(k);
        if (seen === undefined) edges.set(k, [a, b, (v - first) / 3, -1]);
        else if (seen[3] < 0) seen[3] = (v - first) / 3;
        else seen[4] = true;  // three faces meet: draw it
      }
    }
    function faces(t, i) {
      var d = [cam.eye[0] - pos[i], cam.eye[1] - pos[i + 1], cam.eye[2] - pos[i + 2]];
      var tri = first * 3 + t * 9;
      var ax = pos[tri + 3] - pos[tri], ay = pos[tri + 4] - pos[tri + 1], az = pos[tri + 5] - pos[tri + 2];
      var bx = pos[tri + 6] - pos[tri], by = pos[tri + 7] - pos[tri + 1], bz = pos[tri + 8] - pos[tri + 2];
      return dot([ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx], d) > 0;
    }
    edges.forEach(function (e) {
      var draw = e[3] < 0 || e[4];
      if (!draw) {
        var t1 = e[2], t2 = e[3], c1 = first * 3 + t1 * 9, c2 = first * 3 + t2 * 9;
        var cos = normals[3 * t1] * normals[3 * t2] + normals[3 * t1 + 1] * normals[3 * t2 + 1] +
          normals[3 * t1 + 2] * normals[3 * t2 + 2];
        draw = faces(t1, e[0]) !== faces(t2, e[0]) || cos < MODERN.crease ||
          col[c1] !== col[c2] || col[c1 + 1] !== col[c2 + 1] || col[c1 + 2] !== col[c2 + 2];
      }
      if (!draw) return;
      for (var q = 0; q < 3; q++) { lines.push(pos[e[0] + q]); }
      for (q = 0; q < 3; q++) { lines.push(pos[e[1] + q]); }
      var ink = Math.round(255 * MODERN.background * MODERN.ink * 0.5);
      for (q = 0; q < 6; q++) lineCol.push(ink);
    });
  }

  /* Bounds [cx, cy, cz, radius] grown to hold the shadow's square on the ground (near and far planes). */
  function holdingShadow(bounds, m) {
    var r = bounds[3], h = m.extent / 2;
    [[-h, -h], [-h, h], [h, -h], [h, h]].forEach(function (d) {
      var x = m.cx + d[0] - bounds[0], y = m.ground - bounds[1], z = m.cz + d[1] - bounds[2];
      r = Math.max(r, Math.sqrt(x * x + y * y + z * z));
    });
    return [bounds[0], bounds[1], bounds[2], r];
  }

  /* Lay the contact shadow m (LigShadow.compute) on the ground: a square that multiplies the colour
   * under it, behind what is drawn in front of the ground, writing no depth. */
  Renderer.prototype.shadow = function (m, cam, bounds) {
    var gl = this.gl, c = this.canvas, n = LigShadow.params.texels, h = m.extent / 2, y = m.ground;
    var x0 = m.cx - h, x1 = m.cx + h, z0 = m.cz - h, z1 = m.cz + h;
    gl.useProgram(this.shadowProg);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, this.shadowTex);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.LUMINANCE, n, n, 0, gl.LUMINANCE, gl.UNSIGNED_BYTE, m.keep);
    gl.uniform1i(this.sKeep, 0);
    gl.uniform3f(this.sMap, m.cx, m.cz, 1 / m.extent);
    gl.uniformMatrix4fv(this.sM, false, projection(cam, c.width, c.height, bounds).mvp);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.shadowQuad);
    gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([x0, y, z0, x0, y, z1, x1, y, z1, x0, y, z0, x1, y, z1, x1, y, z0]),
      gl.DYNAMIC_DRAW);
    gl.disableVertexAttribArray(this.aC);
    gl.enableVertexAttribArray(this.sP);
    gl.vertexAttribPointer(this.sP, 3, gl.FLOAT, false, 0, 0);
    // The faces sit a little behind their own depth (polygon offset), so a floor at the ground lets the square through.
    gl.disable(gl.POLYGON_OFFSET_FILL);
    gl.depthMask(false);
    gl.enable(gl.BLEND);
    gl.blendFunc(gl.ZERO, gl.SRC_COLOR);
    gl.drawArrays(gl.TRIANGLES, 0, 6);
    gl.disable(gl.BLEND);
    gl.depthMask(true);
    gl.useProgram(this.prog);
    gl.enableVertexAttribArray(this.aP);
    gl.enableVertexAttribArray(this.aC);
  };

  /* Draw one picture.  frame = {pos: Float32Array, col: Uint8Array,
   * ranges: [{first, count, cam}], objects: [{first, count}]} with first/count
   * in vertices; objects are what casts or receives the contact shadow one by
   * one (the figures, the background objects; the ranges when not given). */
  Renderer.prototype.draw = function (frame, bounds) {
    var gl = this.gl, c = this.canvas, modern = this.look === 'modern';
    gl.viewport(0, 0, c.width, c.height);
    var bg = modern ? MODERN.background : 1;
    gl.clearColor(bg, bg, bg, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    gl.enable(gl.DEPTH_TEST);
    // Equal depths: the later triangle wins, as in the rasterizer.
    gl.depthFunc(gl.LEQUAL);
    gl.useProgram(this.prog);
    var n = frame.pos.length;
    var lines = [], lineCol = [], lineRanges = [], shadow = null, shadowCam = null;
    if (modern) {
      var shaded = new Uint8Array(n);
      for (var q = 0; q < frame.ranges.length; q++) {
        var rg = frame.ranges[q];
        if (!rg.count) continue;
        var normals = lit(frame.pos, frame.col, rg.first, rg.count, rg.cam, shaded);
        var l0 = lines.length / 3;
        outlines(frame.pos, frame.col, rg.first, rg.count, rg.cam, normals, lines, lineCol);
        lineRanges.push({ first: l0, count: lines.length / 3 - l0, cam: rg.cam });
        shadowCam = rg.cam;  // the renderer lays the shadow through the picture's last camera
      }
      shadow = LigShadow.compute(frame.pos, frame.objects || frame.ranges);
      if (shadow) bounds = holdingShadow(bounds, shadow);
      frame = { pos: frame.pos, col: shaded, ranges: frame.ranges };
      // Faces a little behind their outlines, so the lines win at equal depth.
      gl.enable(gl.POLYGON_OFFSET_FILL);
      gl.polygonOffset(1, 1);
    } else {
      gl.disable(gl.POLYGON_OFFSET_FILL);
    }
    gl.bindBuffer(gl.ARRAY_BUFFER, this.pos);
    gl.bufferData(gl.ARRAY_BUFFER, frame.pos.subarray(0, n), gl.DYNAMIC_DRAW);
    gl.enableVertexAttribArray(this.aP);
    gl.vertexAttribPointer(this.aP, 3, gl.FLOAT, false, 0, 0);
    gl.bindBuffer(gl.ARRAY_BUFFER, this.col);
    gl.bufferData(gl.ARRAY_BUFFER, frame.col.subarray(0, n), gl.DYNAMIC_DRAW);
    gl.enableVertexAttribArray(this.aC);
    gl.vertexAttribPointer(this.aC, 3, gl.UNSIGNED_BYTE, true, 0, 0);
    for (var i = 0; i < frame.ranges.length; i++) {
      var r = frame.ranges[i];
      if (!r.count) continue;
      gl.uniformMatrix4fv(this.uM, false, projection(r.cam, c.width, c.height, bounds).mvp);
      gl.drawArrays(gl.TRIANGLES, r.first, r.count);
    }
    if (shadow) this.shadow(shadow, shadowCam, bounds);
    this.lastShadow = shadow;
    if (lines.length) {
      gl.bindBuffer(gl.ARRAY_BUFFER, this.linePos);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array(lines), gl.DYNAMIC_DRAW);
      gl.vertexAttribPointer(this.aP, 3, gl.FLOAT, false, 0, 0);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.lineCol);
      gl.bufferData(gl.ARRAY_BUFFER, new Uint8Array(lineCol), gl.DYNAMIC_DRAW);
      gl.vertexAttribPointer(this.aC, 3, gl.UNSIGNED_BYTE, true, 0, 0);
      for (var li = 0; li < lineRanges.length; li++) {
        var lr = lineRanges[li];
        if (!lr.count) continue;
        gl.uniformMatrix4fv(this.uM, false, projection(lr.cam, c.width, c.height, bounds).mvp);
        gl.drawArrays(gl.LINES, lr.first, lr.count);
      }
    }
  };

  /* The nearest triangle under canvas pixel (px, py) (CSS pixels from the
   * top left of a canvas cssW x cssH), or -1.  pos holds world vertices. */
  function pick(px, py, cssW, cssH, cam, pos, first, count) {
    var b = basis(cam);
    var sx = 2 / cam.k, sy = sx * cssW / cssH;
    var nx = (2 * px / cssW - 1) / sx, ny = (1 - 2 * py / cssH) / sy;
    var d = [b.fwd[0] + b.right[0] * nx + b.up[0] * ny, b.fwd[1] + b.right[1] * nx + b.up[1] * ny,
      b.fwd[2] + b.right[2] * nx + b.up[2] * ny];
    var o = cam.eye, best = Infinity, hit = -1;
    var end = first + count;
    for (var v = first; v < end; v += 3) {
      var i = v * 3;
      var e1x = pos[i + 3] - pos[i], e1y = pos[i + 4] - pos[i + 1], e1z = pos[i + 5] - pos[i + 2];
      var e2x = pos[i + 6] - pos[i], e2y = pos[i + 7] - pos[i + 1], e2z = pos[i + 8] - pos[i + 2];
      var hx = d[1] * e2z - d[2] * e2y, hy = d[2] * e2x - d[0] * e2z, hz = d[0] * e2y - d[1] * e2x;
      var a = e1x * hx + e1y * hy + e1z * hz;
      if (a > -1e-20 && a < 1e-20) continue;
      var f = 1 / a;
      var sX = o[0] - pos[i], sY = o[1] - pos[i + 1], sZ = o[2] - pos[i + 2];
      var u = f * (sX * hx + sY * hy + sZ * hz);
      if (u < 0 || u > 1) continue;
      var qx = sY * e1z - sZ * e1y, qy = sZ * e1x - sX * e1z, qz = sX * e1y - sY * e1x;
      var w = f * (d[0] * qx + d[1] * qy + d[2] * qz);
      if (w < 0 || u + w > 1) continue;
      var t = f * (e2x * qx + e2y * qy + e2z * qz);
      if (t > 0 && t <= best) { best = t; hit = (v - first) / 3; }
    }
    return hit;
  }

  /* Orbit, pan and zoom about cam.target, keeping cam.k (the field of view). */
  function orbit(cam, dYaw, dPitch) {
    var v = sub(cam.eye, cam.target), d = norm(v);
    var pitch = Math.asin(Math.max(-1, Math.min(1, v[1] / d)));
    var yaw = Math.atan2(v[0], v[2]);
    if (Math.abs(v[0]) < 1e-12 * d && Math.abs(v[2]) < 1e-12 * d) {
      // Straight above or below: LIG's picture has -Z towards its top.
      yaw = v[1] > 0 ? 0 : Math.PI;
    }
    yaw -= dYaw;
    pitch = Math.max(-1.5697, Math.min(1.5697, pitch + dPitch));
    cam.eye = [cam.target[0] + d * Math.cos(pitch) * Math.sin(yaw), cam.target[1] + d * Math.sin(pitch),
      cam.target[2] + d * Math.cos(pitch) * Math.cos(yaw)];
  }

  function pan(cam, dx, dy, cssW) {
    var b = basis(cam), k = cam.k * b.distance / cssW;
    var m = [(-b.right[0] * dx + b.up[0] * dy) * k, (-b.right[1] * dx + b.up[1] * dy) * k,
      (-b.right[2] * dx + b.up[2] * dy) * k];
    cam.eye = [cam.eye[0] + m[0], cam.eye[1] + m[1], cam.eye[2] + m[2]];
    cam.target = [cam.target[0] + m[0], cam.target[1] + m[1], cam.target[2] + m[2]];
  }

  function zoom(cam, factor) {
    var v = sub(cam.eye, cam.target);
    cam.eye = [cam.target[0] + v[0] * factor, cam.target[1] + v[1] * factor, cam.target[2] + v[2] * factor];
  }

  /* Typed arrays out of the page's base64 blob: refs are {o, n, t}. */
  function decodeBase64(text) {
    var s = atob(text.replace(/\s+/g, ''));
    var n = s.length, out = new Uint8Array(n);
    for (var i = 0; i < n; i++) out[i] = s.charCodeAt(i);
    return out;
  }
  var KINDS = { f32: Float32Array, u8: Uint8Array, u16: Uint16Array, i32: Int32Array, u32: Uint32Array };
  function view(bytes, ref) {
    var K = KINDS[ref.t];
    return new K(bytes.buffer, bytes.byteOffset + ref.o, ref.n);
  }

  return {
    Renderer: Renderer, basis: basis, projection: projection, transform: transform, colours: colours,
    pick: pick, orbit: orbit, pan: pan, zoom: zoom, decodeBase64: decodeBase64, view: view
  };
})();
