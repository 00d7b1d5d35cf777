/* LIG shadow: the modern look's soft contact shadow, as runtime/render/look.py computes it.
 *
 * docs/semantics-render.md ("Looks") gives the rule, which this file
 * follows step for step, once a drawn picture, from the pose drawn:
 * objects at least 20 times as wide or deep as they are high are floors
 * (they receive the shadow and cast none) and the ground is the top of
 * the highest; without one it is the plane y = 0, or the lowest point
 * drawn if lower.  A 64 x 64 height map of the lowest surface above each
 * point of the ground (rasterized here at the texel centres, seen from
 * straight below) gives a darkness of `shadow` where a surface touches the
 * ground, fading linearly to nothing at `reach` times the drawing's height
 * above it, blurred by two box blurs each way of radius 0.35 of that
 * reach.  gl.js lays the map on the ground as a square that multiplies the
 * colour under it (the background, as if the ground went on, and the
 * floors), behind anything drawn in front of the ground.
 */
'use strict';
var LigShadow = (function () {
  /* The parameters of runtime/render/look.py's Look and its constants. */
  var P = { shadow: 0.55, reach: 0.5, texels: 64, floorRatio: 20, margin: 0.8, blur: 0.35 };

  /* Each object's box, [x0, y0, z0, x1, y1, z1]; objects are {first, count} in vertices. */
  function box(pos, o) {
    var b = [Infinity, Infinity, Infinity, -Infinity, -Infinity, -Infinity];
    for (var i = o.first * 3, end = (o.first + o.count) * 3; i < end; i += 3) {
      for (var k = 0; k < 3; k++) {
        var v = pos[i + k];
        if (v < b[k]) b[k] = v;
        if (v > b[k + 3]) b[k + 3] = v;
      }
    }
    return b;
  }

  function isFloor(b) {
    var wide = Math.max(b[3] - b[0], b[5] - b[2]);
    return wide > 0 && (b[4] - b[1]) * P.floorRatio <= wide;
  }

  /* Python's round(): halves to even, as the renderer rounds the blur's radius. */
  function roundHalfEven(x) {
    var r = Math.round(x);
    return Math.abs(x - Math.trunc(x)) === 0.5 && r % 2 !== 0 ? r - 1 : r;
  }

  /* Lowest height above the ground of the casters over each texel centre (Infinity where none). */
  function heights(pos, casters, m) {
    var n = P.texels, h = new Float32Array(n * n).fill(Infinity), s = n / m.extent;
    for (var q = 0; q < casters.length; q++) {
      var o = casters[q];
      for (var i = o.first * 3, end = (o.first + o.count) * 3; i < end; i += 9) {
        // Texel coordinates (centres at integers): column from -x, row from +z, as seen from below.
        var u0 = 0.5 * n - 0.5 - (pos[i] - m.cx) * s, v0 = 0.5 * n - 0.5 + (pos[i + 2] - m.cz) * s;
        var u1 = 0.5 * n - 0.5 - (pos[i + 3] - m.cx) * s, v1 = 0.5 * n - 0.5 + (pos[i + 5] - m.cz) * s;
        var u2 = 0.5 * n - 0.5 - (pos[i + 6] - m.cx) * s, v2 = 0.5 * n - 0.5 + (pos[i + 8] - m.cz) * s;
        var area = (u1 - u0) * (v2 - v0) - (u2 - u0) * (v1 - v0);
        if (!(Math.abs(area) > 1e-12)) continue;  // edge-on from below: covers no texel centre
        var h0 = pos[i + 1] - m.ground, h1 = pos[i + 4] - m.ground, h2 = pos[i + 7] - m.ground;
        var c0 = Math.max(0, Math.ceil(Math.min(u0, u1, u2))), c1 = Math.min(n - 1, Math.floor(Math.max(u0, u1, u2)));
        var r0 = Math.max(0, Math.ceil(Math.min(v0, v1, v2))), r1 = Math.min(n - 1, Math.floor(Math.max(v0, v1, v2)));
        var inv = 1 / area;
        for (var r = r0; r <= r1; r++) {
          for (var c = c0; c <= c1; c++) {
            var w1 = ((c - u0) * (v2 - v0) - (u2 - u0) * (r - v0)) * inv;
            var w2 = ((u1 - u0) * (r - v0) - (c - u0) * (v1 - v0)) * inv;
            var w0 = 1 - w1 - w2;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            var y = w0 * h0 + w1 * h1 + w2 * h2, at = r * n + c;
            if (y < h[at]) h[at] = y;
          }
        }
      }
    }
    return h;
  }

  /* Mean over 2 radius + 1 neighbours along rows (axis 0) or columns (axis 1), zeros beyond the edges. */
  function boxBlur(a, radius, axis) {
    var n = P.texels, out = new Float32Array(n * n), k = 1 / (2 * radius + 1);
    for (var line = 0; line < n; line++) {
      var sum = 0;
      var at = function (i) { return axis === 0 ? i * n + line : line * n + i; };
      for (var i = 0; i < radius && i < n; i++) sum += a[at(i)];
      for (i = 0; i < n; i++) {
        if (i + radius < n) sum += a[at(i + radius)];
        out[at(i)] = sum * k;
        if (i - radius >= 0) sum -= a[at(i - radius)];
      }
    }
    return out;
  }

  /* The shadow of one picture: null, or {keep: Uint8Array (texels^2, 255 * (1 - darkness),
   * row r from +z, column c from -x), cx, cz, ground, extent}. */
  function compute(pos, objects) {
    var boxes = objects.map(function (o) { return box(pos, o); });
    var casters = [], top = -Infinity, lo = Infinity, hi = -Infinity;
    var x0 = Infinity, x1 = -Infinity, z0 = Infinity, z1 = -Infinity;
    for (var q = 0; q < objects.length; q++) {
      var b = boxes[q];
      if (!objects[q].count || !(b[4] >= b[1])) continue;
      if (isFloor(b)) { top = Math.max(top, b[4]); continue; }
      casters.push(objects[q]);
      lo = Math.min(lo, b[1]); hi = Math.max(hi, b[4]);
      x0 = Math.min(x0, b[0]); x1 = Math.max(x1, b[3]); z0 = Math.min(z0, b[2]); z1 = Math.max(z1, b[5]);
    }
    if (!casters.length) return null;
    var ground = top > -Infinity ? top : Math.min(0, lo);
    var reach = P.reach * Math.max(hi - ground, 1e-9);
    x0 -= P.margin * reach; x1 += P.margin * reach; z0 -= P.margin * reach; z1 += P.margin * reach;
    var m = { cx: 0.5 * (x0 + x1), cz: 0.5 * (z0 + z1), ground: ground, extent: Math.max(x1 - x0, z1 - z0) };
    var n = P.texels, h = heights(pos, casters, m), dark = new Float32Array(n * n), any = false;
    for (var t = 0; t < n * n; t++) {
      if (h[t] === Infinity) continue;
      any = true;
      dark[t] = P.shadow * Math.min(1, Math.max(0, 1 - Math.max(h[t], 0) / reach));
    }
    if (!any) return null;
    var radius = Math.max(1, roundHalfEven(P.blur * reach * n / m.extent));
    [0, 1, 0, 1].forEach(function (axis) { dark = boxBlur(dark, radius, axis); });
    m.keep = new Uint8Array(n * n);
    for (t = 0; t < n * n; t++) m.keep[t] = Math.round(255 * (1 - dark[t]));
    return m;
  }

  return { compute: compute, params: P };
})();
