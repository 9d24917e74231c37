(function () {
"use strict";
// viewer.js files are loaded when their run is shown (each is ~1 MB); the
// test mode (#viewer-test) has them all written in by the loader script.
const files = window.BF_VIEWER_FILES || [];
const runs = window.BF_VIEWER = window.BF_VIEWER || {};
const ids = files.map((f) => f.id);
const root = document.getElementById("viewer");
if (!root || ids.length === 0) return;
const testMode = location.hash === "#viewer-test";
const canvas = document.createElement("canvas");
const gl = canvas.getContext("webgl2", {preserveDrawingBuffer: true});
const status = document.getElementById("v-status");
if (!gl) { status.textContent = "WebGL2 is not available in this browser: the viewer cannot run."; return; }
if (!gl.getExtension("EXT_color_buffer_float")) { status.textContent = "EXT_color_buffer_float missing: the viewer cannot read float results."; return; }
const VS = "#version 300 es\nvoid main(){vec2 p=vec2(float((gl_VertexID<<1)&2),float(gl_VertexID&2));gl_Position=vec4(p*2.0-1.0,0.0,1.0);}";
const FS_MAIN = document.getElementById("v-shader-main").textContent;
const {linePlot} = window.BF_PLOT;
function b64floats(s) {
  const bin = atob(s), n = bin.length, bytes = new Uint8Array(n);
  for (let i = 0; i < n; ++i) bytes[i] = bin.charCodeAt(i);
  return new Float32Array(bytes.buffer);
}
function compile(type, src) {
  const s = gl.createShader(type);
  gl.shaderSource(s, src);
  gl.compileShader(s);
  if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
  return s;
}
function texture(w, h, data, rgba) {
  const t = gl.createTexture();
  gl.bindTexture(gl.TEXTURE_2D, t);
  gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
  if (rgba) gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, w, h, 0, gl.RGBA, gl.FLOAT, data);
  else gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGB32F, w, h, 0, gl.RGB, gl.FLOAT, data);
  for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
  for (const p of [gl.TEXTURE_WRAP_S, gl.TEXTURE_WRAP_T]) gl.texParameteri(gl.TEXTURE_2D, p, gl.CLAMP_TO_EDGE);
  return t;
}
// Gauss-Legendre nodes and weights on [a, b] (Newton on P_n from Chebyshev
// starts; converged to double precision).
function gaussLegendre(n, a, b) {
  const x = [], w = [];
  for (let i = 0; i < n; ++i) {
    let z = Math.cos(Math.PI * (i + 0.75) / (n + 0.5)), dp = 1;
    for (let it = 0; it < 100; ++it) {
      let p0 = 1, p1 = z;
      for (let k = 2; k <= n; ++k) { const p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k; p0 = p1; p1 = p2; }
      dp = n * (z * p1 - p0) / (z * z - 1);
      const dz = p1 / dp;
      z -= dz;
      if (Math.abs(dz) < 1e-15) break;
    }
    x.push(a + (b - a) * (1 - z) / 2);  // ascending
    w.push((b - a) / ((1 - z * z) * dp * dp));
  }
  return {x, w};
}
// The hemisphere rule of the albedo curves: ALBEDO_NZ Gauss-Legendre nodes in
// cos theta on [0, 1] times ALBEDO_NPHI uniform phi = 2 pi (j + 1/2) / NPHI
// (the library's sphere_rule(NZ, NPHI, 0, 1)), as RGBA floats (direction,
// weight), node k = i NPHI + j. 64 x 128: within 6e-3 of a 512 x 1024 rule
// for Cook-Torrance's default lobe at grazing theta_o (32 x 64: 0.046;
// 128 x 256: 1e-4 but four times slower in software WebGL2).
const ALBEDO_NZ = 64, ALBEDO_NPHI = 128, ALBEDO_N = 90, ALBEDO_CHUNK = 2048;
function hemisphereRule(nz, nphi) {
  const g = gaussLegendre(nz, 0, 1), out = new Float32Array(nz * nphi * 4);
  for (let i = 0; i < nz; ++i)
    for (let j = 0; j < nphi; ++j) {
      const z = g.x[i], r = Math.sqrt(Math.max(0, (1 - z) * (1 + z))), ph = 2 * Math.PI * (j + 0.5) / nphi, k = 4 * (i * nphi + j);
      out[k] = r * Math.cos(ph); out[k + 1] = r * Math.sin(ph); out[k + 2] = z; out[k + 3] = g.w[i] * 2 * Math.PI / nphi;
    }
  return out;
}
let aruleTex = null;
const cache = {};
function setup(id) {
  if (cache[id]) return cache[id];
  const r = runs[id];
  const fs = "#version 300 es\n#define BRDF_FACTOR_EXACT_BILINEAR\nprecision highp float;\nprecision highp int;\n" +
             r.glsl + "\nconst int BF_ORIG_RES = " + (r.original.res || 2) + ";\nconst int BF_ORIG_KIND = " +
             (r.original.kind === "iso" ? 1 : 0) + ";\nconst int BF_ORIG_NH = " + (r.original.nh || 2) +
             ", BF_ORIG_ND = " + (r.original.nd || 2) + ", BF_ORIG_NP = " + (r.original.np || 2) + ";\n" + FS_MAIN;
  const prog = gl.createProgram();
  gl.attachShader(prog, compile(gl.VERTEX_SHADER, VS));
  gl.attachShader(prog, compile(gl.FRAGMENT_SHADER, fs));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  const units = [];
  r.textures.forEach((t) => { units.push({name: t.sampler, tex: texture(t.width, t.height, b64floats(t.data)), values: null}); });
  const o = r.original;
  units.push({name: "bf_orig", tex: o.kind === "iso" ? texture(o.np * o.nd, o.nh, b64floats(o.data))
                                                    : texture(o.res * o.res, o.res * o.res, b64floats(o.data))});
  const e = r.environment;
  units.push({name: "bf_env", tex: e ? texture(e.width, e.height, b64floats(e.data)) : texture(2, 2, new Float32Array(12))});
  units.push({name: "bf_rule", tex: e ? texture(e.nodes, 1, b64floats(e.rule), true) : texture(1, 1, new Float32Array(4), true)});
  aruleTex = aruleTex || texture(ALBEDO_NPHI, ALBEDO_NZ, hemisphereRule(ALBEDO_NZ, ALBEDO_NPHI), true);
  units.push({name: "bf_arule", tex: aruleTex});
  cache[id] = {prog, units};
  return cache[id];
}
// Renders one mode into a w x h float target; returns RGBA floats, row 0 = top.
function run(id, mode, which, w, h, u) {
  const s = setup(id), r = runs[id];
  const fb = gl.createFramebuffer(), rb = gl.createRenderbuffer();
  gl.bindRenderbuffer(gl.RENDERBUFFER, rb);
  gl.renderbufferStorage(gl.RENDERBUFFER, gl.RGBA32F, w, h);
  gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
  gl.framebufferRenderbuffer(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.RENDERBUFFER, rb);
  gl.viewport(0, 0, w, h);
  gl.useProgram(s.prog);
  // A loaded environment map (u.hdr) replaces the scene's lighting textures.
  const hdr = u.env && u.hdr ? u.hdr : null;
  s.units.forEach((t, k) => {
    gl.activeTexture(gl.TEXTURE0 + k);
    gl.bindTexture(gl.TEXTURE_2D, hdr && t.name === "bf_env" ? hdr.env : hdr && t.name === "bf_rule" ? hdr.rule : t.tex);
    gl.uniform1i(gl.getUniformLocation(s.prog, t.name), k);
  });
  const L = (n) => gl.getUniformLocation(s.prog, n);
  gl.uniform1i(L("u_mode"), mode);
  gl.uniform1i(L("u_which"), which);
  gl.uniform2f(L("u_size"), w, h);
  gl.uniform3fv(L("u_light"), u.light);
  gl.uniform1f(L("u_intensity"), u.intensity !== undefined ? u.intensity : r.scene.intensity);
  gl.uniformMatrix3fv(L("u_cam"), false, u.cam);
  gl.uniform1f(L("u_theta_i"), u.theta_i);
  gl.uniform1f(L("u_phi_d"), u.phi_d);
  gl.uniform1i(L("u_env"), hdr || (u.env && r.environment) ? 1 : 0);
  gl.uniform1i(L("u_rule_n"), hdr ? hdr.nodes : r.environment ? r.environment.nodes : 0);
  // u.env_rot is R row-major; read as column-major it is R^T, the lookup matrix.
  gl.uniformMatrix3fv(L("u_env_rot"), false, u.env_rot || [1, 0, 0, 0, 1, 0, 0, 0, 1]);
  gl.uniform1i(L("u_out_of_plane"), u.out_of_plane ? 1 : 0);
  gl.uniform1i(L("u_shape"), u.shape === "torus" ? 1 : 0);
  gl.uniform1i(L("u_arule_first"), u.arule_first || 0);
  gl.uniform1i(L("u_arule_n"), u.arule_n || 0);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  const px = new Float32Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, px);
  // A lost context (e.g. the browser's GPU watchdog) reads back zeros: say so.
  if (gl.isContextLost()) throw new Error("the WebGL context was lost: reload the page");
  gl.bindFramebuffer(gl.FRAMEBUFFER, null);
  gl.deleteFramebuffer(fb);
  gl.deleteRenderbuffer(rb);
  const out = new Float32Array(w * h * 4);
  for (let y = 0; y < h; ++y) out.set(px.subarray((h - 1 - y) * w * 4, (h - y) * w * 4), y * w * 4);
  return out;
}
function srgb(v) { v = Math.min(1, Math.max(0, v)); return v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055; }
const STOPS = [[0, 0, 0], [0.1, 0.15, 0.85], [0.9, 0.1, 0.2], [1, 0.85, 0.1], [1, 1, 1]];
function heat(t) {
  t = Math.min(1, Math.max(0, t)) * 4;
  const i = Math.min(3, Math.floor(t)), u = t - i;
  return STOPS[i].map((a, c) => a * (1 - u) + STOPS[i + 1][c] * u);
}
function fmt(v) { return Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(1) : (+v.toPrecision(3)).toString(); }
function put(cv, w, h, colour) {
  cv.width = w; cv.height = h;
  const ctx = cv.getContext("2d"), img = ctx.createImageData(w, h);
  for (let k = 0; k < w * h; ++k) {
    const c = colour(k);
    img.data[4 * k] = Math.round(255 * c[0]); img.data[4 * k + 1] = Math.round(255 * c[1]);
    img.data[4 * k + 2] = Math.round(255 * c[2]); img.data[4 * k + 3] = 255;
  }
  ctx.putImageData(img, 0, 0);
}
// A horizontal colour bar with labelled ends and middle.
function bar(cv, label, lo, hi, ramp, log) {
  const w = 300, h = 44;
  cv.width = w; cv.height = h;
  const ctx = cv.getContext("2d");
  for (let x = 0; x < w; ++x) {
    const c = ramp(x / (w - 1));
    ctx.fillStyle = "rgb(" + c.map((v) => Math.round(255 * v)).join(",") + ")";
    ctx.fillRect(x, 0, 1, 14);
  }
  ctx.fillStyle = "#222"; ctx.font = "11px sans-serif";
  const mid = log ? Math.sqrt(lo * hi) : 0.5 * (lo + hi);
  ctx.textAlign = "left"; ctx.fillText(fmt(lo), 0, 26);
  ctx.textAlign = "center"; ctx.fillText(fmt(mid), w / 2, 26);
  ctx.textAlign = "right"; ctx.fillText(fmt(hi), w, 26);
  ctx.textAlign = "center"; ctx.fillText(label, w / 2, 40);
}
const state = {id: null, light: null, cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], yaw: 0, pitch: 0, exposure: 1,
               theta_i: 30 * Math.PI / 180, phi_d: Math.PI / 2, env: true, channel: "mean", log: true,
               hdr: null, hdrExposure: null, shape: "sphere"};
const $ = (q) => document.getElementById(q);
function camMatrix() {
  const cy = Math.cos(state.yaw), sy = Math.sin(state.yaw), cp = Math.cos(state.pitch), sp = Math.sin(state.pitch);
  // world = Ry(yaw) Rx(pitch) camera, column-major for uniformMatrix3fv.
  return [cy, 0, -sy, sy * sp, cp, cy * sp, sy * cp, -sp, cy * cp];
}
const unit = (v) => { const n = Math.hypot(...v); return v.map((x) => x / n); };
// The smallest rotation R with R a = b (unit vectors; row-major 3x3), about
// a x b (Rodrigues: R = c I + s [k]x + (1 - c) k k^T); a half turn about an
// axis normal to a when b = -a.
function rotation(a, b) {
  let c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  let k = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  let s = Math.hypot(...k);
  if (s < 1e-9) {
    if (c > 0) return [1, 0, 0, 0, 1, 0, 0, 0, 1];
    k = Math.abs(a[0]) < 0.9 ? [0, a[2], -a[1]] : [-a[2], 0, a[0]];  // a x (1,0,0) or a x (0,1,0)
    s = 0; c = -1;
  }
  k = unit(k);
  const K = [0, -k[2], k[1], k[2], 0, -k[0], -k[1], k[0], 0], R = [];
  for (let i = 0; i < 3; ++i)
    for (let j = 0; j < 3; ++j) R.push((i === j ? c : 0) + s * K[3 * i + j] + (1 - c) * k[i] * k[j]);
  return R;
}
// With the scene's environment, moving the light turns the environment by the
// rotation that takes the scene's light direction to the light's.
function envRotation(light) { return rotation(unit(runs[state.id].scene.light), unit(light)); }
function uniforms() {
  return {light: state.light, cam: state.cam, theta_i: state.theta_i, phi_d: state.phi_d, env: state.env,
          env_rot: envRotation(state.light), hdr: state.hdr, shape: state.shape};
}
// Directional albedo of the original (which = 0) or the approximation (1) at
// ALBEDO_N theta_o (degrees (k + 1/2) 90 / N, phi_o = 0): RGB per theta_o.
// Computed once per run.
const albedoCache = {};
function albedoCurve(id, which) {
  const key = id + "/" + which;
  if (!albedoCache[key]) {
    // In draws of ALBEDO_CHUNK nodes each (a long draw call can trip the
    // browser's GPU watchdog in software WebGL), summed here.
    const rgb = Array.from({length: ALBEDO_N}, () => [0, 0, 0]);
    for (let first = 0; first < ALBEDO_NZ * ALBEDO_NPHI; first += ALBEDO_CHUNK) {
      const a = run(id, 3, which, ALBEDO_N, 1, {light: [0, 0, 1], cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], theta_i: 0, phi_d: 0,
                                                arule_first: first, arule_n: Math.min(ALBEDO_CHUNK, ALBEDO_NZ * ALBEDO_NPHI - first)});
      for (let k = 0; k < ALBEDO_N; ++k) for (let c = 0; c < 3; ++c) rgb[k][c] += a[4 * k + c];
    }
    albedoCache[key] = rgb;
  }
  return albedoCache[key];
}
const albedoX = Array.from({length: ALBEDO_N}, (_, k) => (k + 0.5) * 90 / ALBEDO_N);
function channelValue(rgb) { return state.channel === "mean" ? (rgb[0] + rgb[1] + rgb[2]) / 3 : rgb[Number(state.channel)]; }
function channelName() { return state.channel === "mean" ? "mean RGB" : "RGB"[Number(state.channel)]; }
// The albedo plot: the original and the approximation against theta_o, the
// region albedo > 1 shaded red, the theta_o where a curve enters it listed.
function drawAlbedo(id) {
  const curves = [["original", 0, []], ["approximation", 1, [5, 3]]].map(([label, which, dash]) =>
    ({label, dash, x: albedoX, y: albedoCurve(id, which).map(channelValue)}));
  const top = Math.max(1.1, 1.05 * Math.max(...curves.map((c) => Math.max(...c.y))));
  linePlot($("v-albedo"), curves, {xmin: 0, xmax: 90, xticks: [0, 15, 30, 45, 60, 75, 90], xlabel: "theta_o (deg), phi_o = 0",
                                   ylabel: "albedo (" + channelName() + ")", log: false, ymax: top,
                                   band: {y0: 1, y1: top, colour: "rgba(214, 39, 40, 0.12)"}});
  const over = curves.map((c) => {
    const k = c.y.findIndex((v) => v > 1);
    return k < 0 ? c.label + ": albedo <= 1 everywhere" : c.label + ": albedo > 1 from theta_o = " + albedoX[k].toFixed(1) + " deg";
  });
  $("v-albedo-note").textContent = over.join("; ") + " (shaded: albedo > 1).";
}
// Cartesian slices: f against theta_o in [-90, 90] at the theta_i slider, in
// the incidence plane and normal to it, original solid, approximation dashed;
// the chosen channel, log (4 decades below the peak) or linear.
const CART_N = 181;
const cartX = Array.from({length: CART_N}, (_, k) => -90 + 180 * (k + 0.5) / CART_N);
function cartSeries(id, which, outOfPlane, u) {
  const P = run(id, 2, which, CART_N, 1, Object.assign({}, u, {out_of_plane: outOfPlane}));
  const y = [];
  for (let k = 0; k < CART_N; ++k) y.push(channelValue([P[4 * k], P[4 * k + 1], P[4 * k + 2]]));
  return y;
}
function drawCartesian(entries, u, canvases) {
  for (const [cid, out] of [[canvases[0], false], [canvases[1], true]]) {
    const series = entries.map((e) => ({label: e.label, dash: e.dash, colour: e.colour, x: cartX, y: cartSeries(e.id, e.which, out, u)}));
    let peak = 0;
    for (const s of series) for (const v of s.y) peak = Math.max(peak, v);
    peak = peak > 0 ? peak : 1;
    linePlot($(cid), series, {xmin: -90, xmax: 90, xticks: [-90, -60, -30, 0, 30, 60, 90],
                              xlabel: "theta_o (deg), " + (out ? "phi_o = 90 (normal to the incidence plane)" : "phi_o = 0 (incidence plane)"),
                              ylabel: "f (1/sr, " + channelName() + ")", log: state.log, ymin: peak * 1e-4, ymax: peak * 1.1});
    $(cid).dataset.thetaI = String(u.theta_i);
  }
}
// Every redraw; an error (a shader that does not compile, a lost context) is
// shown in the status line instead of leaving stale or blank panels unexplained.
function draw() {
  try {
    drawAll();
  } catch (e) { status.textContent = "viewer error: " + e.message; }
}
function whiteOf(A) {
  const peaks = [];
  for (let k = 0; k < A.length / 4; ++k) if (A[4 * k + 3]) peaks.push(Math.max(A[4 * k], A[4 * k + 1], A[4 * k + 2]));
  peaks.sort((a, b) => a - b);
  const p = peaks.length ? peaks[Math.min(peaks.length - 1, Math.floor(0.99 * peaks.length))] : 0;
  return p > 0 && isFinite(p) ? 1 / p : 1;
}
function drawAll() {
  const id = state.id, r = runs[id], n = 160;
  const u = uniforms();
  let A, B;
  try {
    A = run(id, 0, 0, n, n, u);
    B = run(id, 0, 1, n, n, u);
  } catch (e) { status.textContent = "shader error: " + e.message; return; }
  // Under a loaded map the run's exposure (set for its point light) does not
  // fit: 1 / the 99th percentile of the original's brightest channel under
  // the map, as sphere.png's rule, shared with compare mode.
  state.hdrExposure = state.env && state.hdr ? whiteOf(A) : null;
  const expo = (state.hdrExposure || r.exposure) * state.exposure;
  const bg = [0.16, 0.16, 0.16];
  put($("v-orig"), n, n, (k) => A[4 * k + 3] ? [0, 1, 2].map((c) => srgb(A[4 * k + c] * expo)) : bg);
  put($("v-approx"), n, n, (k) => A[4 * k + 3] ? [0, 1, 2].map((c) => srgb(B[4 * k + c] * expo)) : bg);
  put($("v-diff"), n, n, (k) => {
    if (!A[4 * k + 3]) return bg;
    let e = 0;
    for (let c = 0; c < 3; ++c) e += Math.abs(B[4 * k + c] - A[4 * k + c]) / 3;
    return heat(e * expo / 0.25);
  });
  bar($("v-bar-rad"), "radiance (white)", 0, 1 / expo, (t) => [srgb(t), srgb(t), srgb(t)], false);
  bar($("v-bar-diff"), "|difference|", 0, 0.25 / expo, heat, false);
  // theta_h - theta_d slices at the phi_d slider: the chosen channel (or the
  // mean of R, G, B), log colour over 4 decades below the original's peak or
  // linear from 0 to it.
  const m = 90;
  const S0 = run(id, 1, 0, m, m, u), S1 = run(id, 1, 1, m, m, u);
  const value = (S, k) => state.channel === "mean" ? (S[4 * k] + S[4 * k + 1] + S[4 * k + 2]) / 3
                                                   : S[4 * k + Number(state.channel)];
  let peak = 0;
  for (let k = 0; k < m * m; ++k) peak = Math.max(peak, value(S0, k));
  peak = peak > 0 ? peak : 1;
  const lo = state.log ? peak * 1e-4 : 0;
  const scale = state.log ? (v) => heat((Math.log10(Math.max(v, lo)) - Math.log10(lo)) / 4) : (v) => heat(v / peak);
  put($("v-slice-orig"), m, m, (k) => scale(value(S0, k)));
  put($("v-slice-approx"), m, m, (k) => scale(value(S1, k)));
  const chName = state.channel === "mean" ? "mean RGB" : "RGB"[Number(state.channel)];
  bar($("v-bar-slice"), "f (1/sr, " + chName + ", " + (state.log ? "log" : "linear") + ")", lo, peak, (t) => heat(t), state.log);
  // In-plane lobes, polar plot.
  const N = 181, P0 = run(id, 2, 0, N, 1, u), P1 = run(id, 2, 1, N, 1, u);
  const cv = $("v-lobe"), ctx = cv.getContext("2d"), W = cv.width, H = cv.height;
  ctx.clearRect(0, 0, W, H);
  let fmax = 0;
  for (let k = 0; k < N; ++k) for (const P of [P0, P1]) fmax = Math.max(fmax, (P[4 * k] + P[4 * k + 1] + P[4 * k + 2]) / 3);
  fmax = fmax > 0 ? fmax : 1;
  const cx = W / 2, cy = H - 20, rad = Math.min(W / 2, H - 30) - 10;
  ctx.strokeStyle = "#ccc"; ctx.beginPath(); ctx.arc(cx, cy, rad, Math.PI, 2 * Math.PI); ctx.stroke();
  ctx.beginPath(); ctx.moveTo(cx, cy); ctx.lineTo(cx + rad * Math.sin(state.theta_i), cy - rad * Math.cos(state.theta_i)); ctx.stroke();
  for (const [P, style, dash] of [[P0, "#1f77b4", []], [P1, "#d62728", [5, 3]]]) {
    ctx.strokeStyle = style; ctx.setLineDash(dash); ctx.lineWidth = 1.5; ctx.beginPath();
    for (let k = 0; k < N; ++k) {
      const to = -Math.PI / 2 + Math.PI * (k + 0.5) / N, v = (P[4 * k] + P[4 * k + 1] + P[4 * k + 2]) / 3 / fmax;
      const x = cx + rad * v * Math.sin(to), y = cy - rad * v * Math.cos(to);
      if (k) ctx.lineTo(x, y); else ctx.moveTo(x, y);
    }
    ctx.stroke();
  }
  ctx.setLineDash([]); ctx.fillStyle = "#222"; ctx.font = "11px sans-serif";
  ctx.fillText("radius: f (mean RGB), full scale " + fmt(fmax) + " 1/sr; grey: light at " +
               Math.round(state.theta_i * 180 / Math.PI) + " deg", 6, H - 4);
  drawAlbedo(id);
  drawCartesian([{id, which: 0, label: "original", colour: "#1f77b4"}, {id, which: 1, label: "approximation", colour: "#d62728", dash: [5, 3]}], u,
                ["v-cart-in", "v-cart-out"]);
  drawCompare();
  const turned = ", turned " + Math.round(Math.acos(Math.min(1, Math.max(-1, (u.env_rot[0] + u.env_rot[4] + u.env_rot[8] - 1) / 2))) *
                                         180 / Math.PI) + " deg with the light";
  $("v-info").textContent = r.label + " (" + r.method + "), " +
      (state.env && state.hdr ? "lit by " + state.hdr.name + " (" + state.hdr.width + " x " + state.hdr.height + ", SH order " +
                                state.hdr.order + ", " + state.hdr.nodes + " hemisphere nodes per pixel)" + turned
      : state.env && r.environment ? "lit by the scene's SH lighting (" + r.environment.nodes + " hemisphere nodes per pixel)" + turned
                                  : "point light (" + state.light.map((v) => v.toFixed(2)).join(", ") + ")") +
      ", " + state.shape + ", view yaw " + Math.round(state.yaw * 180 / Math.PI) + " pitch " + Math.round(state.pitch * 180 / Math.PI) + " deg";
  // Factor textures with their value scale.
  const tx = $("v-textures");
  tx.textContent = r.textures.length ? "" : "No factor textures: the " +
      (r.method === "model-fit" ? "fitted parameters" : "coefficients") + " are constants of the GLSL.";
  r.textures.forEach((t) => {
    const d = b64floats(t.data);
    let a = Number.MAX_VALUE, b = -Number.MAX_VALUE;
    for (let k = 0; k < t.width * t.height; ++k) { const v = (d[3 * k] + d[3 * k + 1] + d[3 * k + 2]) / 3; if (v !== 0) { a = Math.min(a, v); b = Math.max(b, v); } }
    if (!(a < b)) { a = 0; b = 1; }
    const fig = document.createElement("figure"), c1 = document.createElement("canvas"), c2 = document.createElement("canvas");
    put(c1, t.width, t.height, (k) => heat(((d[3 * k] + d[3 * k + 1] + d[3 * k + 2]) / 3 - a) / (b - a)));
    c1.style.width = Math.min(512, Math.max(128, t.width * 4)) + "px";
    c1.style.imageRendering = "pixelated";
    bar(c2, t.sampler + " (mean RGB)", a, b, heat, false);
    fig.appendChild(c1); fig.appendChild(document.createElement("br")); fig.appendChild(c2);
    tx.appendChild(fig);
  });
}
// Compare mode: any two or more entries (a run's approximation, or the
// original BRDF of a run) side by side under one point light (the shown run's
// light and intensity, moved by dragging its spheres) and one exposure (the
// shown run's times the slider); their Cartesian slices and albedo curves
// overlaid with a legend; the difference of two of them (A - B, per channel;
// shown as mean |A - B| in the heat map of the |difference| panel).
const cmp = {picked: [], a: 0, b: 1, size: 160, last: null};
function entryLabel(e) { return e.id + " " + (e.which ? "approx." : "original") + ": " + files.find((f) => f.id === e.id).label; }
function drawCompare() {
  const box = $("v-cmp-out");
  if (!box) return;
  const picked = cmp.picked.filter((e) => runs[e.id]);
  if (picked.length < 2 || !state.id) {
    box.hidden = true;
    cmp.last = null;
    return;
  }
  box.hidden = false;
  const n = cmp.size, r = runs[state.id], expo = (state.hdrExposure || r.exposure) * state.exposure, bg = [0.16, 0.16, 0.16];
  // The shared light: the point light, or a loaded map (not a run's own scene lighting).
  const u = Object.assign(uniforms(), {env: state.env && !!state.hdr, intensity: r.scene.intensity});
  const spheres = picked.map((e) => run(e.id, 0, e.which, n, n, u));
  const row = $("v-cmp-spheres");
  row.textContent = "";
  picked.forEach((e, i) => {
    const fig = document.createElement("figure"), cv = document.createElement("canvas"), cap = document.createElement("figcaption");
    cv.className = "vcmp";
    put(cv, n, n, (k) => spheres[i][4 * k + 3] ? [0, 1, 2].map((c) => srgb(spheres[i][4 * k + c] * expo)) : bg);
    cap.textContent = String.fromCharCode(65 + i) + ": " + entryLabel(e);
    fig.appendChild(cv); fig.appendChild(cap); row.appendChild(fig);
  });
  for (const [sid, k] of [["v-cmp-a", "a"], ["v-cmp-b", "b"]]) {
    const el = $(sid);
    el.textContent = "";
    picked.forEach((e, i) => {
      const o = document.createElement("option");
      o.value = String(i); o.textContent = String.fromCharCode(65 + i) + ": " + entryLabel(e);
      el.appendChild(o);
    });
    if (!(cmp[k] < picked.length)) cmp[k] = k === "a" ? 0 : 1;
    el.value = String(cmp[k]);
  }
  const A = spheres[cmp.a], B = spheres[cmp.b], diff = new Float32Array(n * n * 3);
  for (let k = 0; k < n * n; ++k) for (let c = 0; c < 3; ++c) diff[3 * k + c] = A[4 * k + c] - B[4 * k + c];
  put($("v-cmp-diff"), n, n, (k) => {
    if (!A[4 * k + 3]) return bg;
    return heat((Math.abs(diff[3 * k]) + Math.abs(diff[3 * k + 1]) + Math.abs(diff[3 * k + 2])) / 3 * expo / 0.25);
  });
  bar($("v-cmp-bar"), "|" + String.fromCharCode(65 + cmp.a) + " - " + String.fromCharCode(65 + cmp.b) + "| (mean RGB)", 0, 0.25 / expo, heat, false);
  const entries = picked.map((e, i) => ({id: e.id, which: e.which, label: String.fromCharCode(65 + i) + ": " + entryLabel(e),
                                         dash: e.which ? [] : [5, 3]}));
  drawCartesian(entries, u, ["v-cmp-in", "v-cmp-out-plane"]);
  linePlot($("v-cmp-albedo"), entries.map((e) => ({label: e.label, dash: e.dash, x: albedoX, y: albedoCurve(e.id, e.which).map(channelValue)})),
           {xmin: 0, xmax: 90, xticks: [0, 15, 30, 45, 60, 75, 90], xlabel: "theta_o (deg), phi_o = 0", ylabel: "albedo (" + channelName() + ")",
            log: false, ymax: Math.max(1.1, ...entries.map((e) => 1.05 * Math.max(...albedoCurve(e.id, e.which).map(channelValue)))),
            band: {y0: 1, y1: 1e9, colour: "rgba(214, 39, 40, 0.12)"}});
  cmp.last = {entries: picked, spheres, diff, size: n};
}
// Loads every picked run's viewer.js, then draws.
function pickCompare() {
  cmp.picked = Array.from(document.querySelectorAll("#v-cmp-list input:checked")).map((el) => ({id: el.dataset.run, which: Number(el.dataset.which)}));
  const missing = cmp.picked.map((e) => e.id).filter((id) => !runs[id]);
  if (missing.length) ensure(missing[0], pickCompare);
  else drawCompare();
}
{
  const list = $("v-cmp-list"), seen = new Set();
  files.forEach((f) => {
    const brdf = f.label.split(" | ")[0];
    const kinds = seen.has(brdf) ? [1] : [1, 0];
    seen.add(brdf);
    for (const which of kinds) {
      const lab = document.createElement("label"), box = document.createElement("input");
      box.type = "checkbox"; box.dataset.run = f.id; box.dataset.which = String(which);
      box.onchange = pickCompare;
      lab.appendChild(box);
      lab.appendChild(document.createTextNode(" " + entryLabel({id: f.id, which}) + (which ? "" : " (the BRDF, tabulated)")));
      list.appendChild(lab);
    }
  });
  $("v-cmp-a").onchange = (e) => { cmp.a = Number(e.target.value); drawCompare(); };
  $("v-cmp-b").onchange = (e) => { cmp.b = Number(e.target.value); drawCompare(); };
}
// A Radiance .hdr picked in the page lights every sphere (the shown run's and
// compare mode's): band-limited to SH order HDR_ORDER as the toolkit's scene
// lighting (hdr.js), shaded by the run's exported GLSL with LitShader's rule.
const HDR_ORDER = 8, HDR_GRID = 128;
function useHdr(map, name) {
  const nz = Math.max(16, HDR_ORDER + 8);
  state.hdr = {name, width: map.width, height: map.height, order: HDR_ORDER, nodes: nz * 2 * nz,
               env: texture(HDR_GRID, HDR_GRID / 2, window.BF_HDR.bandLimited(map, HDR_ORDER, HDR_GRID)),
               rule: texture(nz * 2 * nz, 1, hemisphereRule(nz, 2 * nz), true)};
  state.env = true;
  $("v-env").checked = true;
  $("v-env").disabled = false;
  if (state.id) draw();
}
// The bytes of a picked file: parsed, band-limited and drawn, or refused in
// the status line (the lighting unchanged).
function loadHdrBytes(bytes, name) {
  try {
    useHdr(window.BF_HDR.parseHdr(bytes, name), name);
    status.textContent = "";
  } catch (err) { status.textContent = err.message; }
}
$("v-hdr").onchange = (e) => {
  const f = e.target.files[0];
  if (!f) return;
  status.textContent = "reading " + f.name + " ...";
  const rd = new FileReader();
  rd.onload = () => loadHdrBytes(new Uint8Array(rd.result), f.name);
  rd.onerror = () => { status.textContent = f.name + ": cannot read the file"; };
  rd.readAsArrayBuffer(f);
};
// Controls.
const sel = $("v-run");
files.forEach((f) => { const o = document.createElement("option"); o.value = f.id; o.textContent = f.id + "  " + f.label; sel.appendChild(o); });
function ensure(id, then) {
  if (runs[id]) { then(); return; }
  const f = files.find((x) => x.id === id);
  status.textContent = "loading " + f.path + " ...";
  const el = document.createElement("script");
  el.onload = () => { if (runs[id]) then(); else status.textContent = f.path + " did not define run " + id; };
  el.onerror = () => { status.textContent = "cannot load " + f.path; };
  el.src = f.path;
  document.body.appendChild(el);
}
function show(id) {
  ensure(id, () => {
    state.id = id;
    sel.value = id;
    state.light = runs[id].scene.light.slice();
    $("v-env").disabled = !runs[id].environment && !state.hdr;
    status.textContent = "";
    draw();
  });
}
sel.onchange = () => show(sel.value);
$("v-env").onchange = (e) => { state.env = e.target.checked; draw(); };
$("v-exposure").oninput = (e) => { state.exposure = Math.pow(2, +e.target.value); draw(); };
$("v-theta").oninput = (e) => {
  state.theta_i = +e.target.value * Math.PI / 180;
  $("v-theta-val").textContent = e.target.value;
  draw();
};
$("v-phid").oninput = (e) => {
  state.phi_d = +e.target.value * Math.PI / 180;
  $("v-phid-val").textContent = e.target.value;
  draw();
};
$("v-channel").onchange = (e) => { state.channel = e.target.value; draw(); };
$("v-shape").onchange = (e) => { state.shape = e.target.value; draw(); };
$("v-log").onchange = (e) => { state.log = e.target.checked; draw(); };
$("v-reset").onclick = () => { state.light = runs[state.id].scene.light.slice(); state.yaw = state.pitch = 0; state.cam = camMatrix(); draw(); };
for (const pid of ["v-orig", "v-approx", "v-diff"]) {
  const cv = $(pid);
  let down = false;
  const move = (e) => {
    const b = cv.getBoundingClientRect();
    const x = 2 * (e.clientX - b.left) / b.width - 1, y = 1 - 2 * (e.clientY - b.top) / b.height;
    if (e.shiftKey) {
      state.yaw = x * Math.PI / 2; state.pitch = -y * Math.PI / 2; state.cam = camMatrix();
    } else {
      const d = Math.hypot(...runs[state.id].scene.light), rr = Math.min(1, x * x + y * y);
      const v = [x, y, Math.sqrt(1 - rr)], c = state.cam;
      state.light = [0, 1, 2].map((i) => d * (c[i] * v[0] + c[3 + i] * v[1] + c[6 + i] * v[2]));
    }
    draw();
  };
  cv.onpointerdown = (e) => { down = true; move(e); };
  cv.onpointermove = (e) => { if (down) move(e); };
  window.addEventListener("pointerup", () => { down = false; });
}
if (testMode) {
  // Numbers for the headless test: per run the sphere radiance of both BRDFs
  // at the scene's size and light, and the approximation's slices.
  const out = [];
  for (const id of ids) {
    const r = runs[id], n = r.scene.size, u = {light: r.scene.light, cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], theta_i: 30 * Math.PI / 180, phi_d: Math.PI / 2};
    const rec = {run: id, size: n};
    try {
      const pick = (a, w, h) => { const v = []; for (let k = 0; k < w * h; ++k) v.push(a[4 * k], a[4 * k + 1], a[4 * k + 2]); return v; };
      rec.approx = pick(run(id, 0, 1, n, n, u), n, n);
      rec.original = pick(run(id, 0, 0, n, n, u), n, n);
      rec.slice = pick(run(id, 1, 1, 16, 16, u), 16, 16);
      rec.lobe = pick(run(id, 2, 1, 32, 1, u), 32, 1);
      rec.lobe_original = pick(run(id, 2, 0, 32, 1, u), 32, 1);
      // Albedo curves (8192 nodes x 90 theta_o each, slow in software
      // WebGL): the first run's, which the page draws.
      if (id === ids[0]) {
        rec.albedo = [].concat(...albedoCurve(id, 1));
        rec.albedo_original = [].concat(...albedoCurve(id, 0));
      }
      if (r.environment) {
        const ue = Object.assign({}, u, {env: true});
        rec.approx_env = pick(run(id, 0, 1, n, n, ue), n, n);
        // The light dragged to (-0.4, 0.5, 0.75) (direction): the environment turns with it.
        state.id = id;
        rec.env_rot = envRotation([-0.4, 0.5, 0.75]);
        rec.approx_env_turned = pick(run(id, 0, 1, n, n, Object.assign({}, ue, {env_rot: rec.env_rot})), n, n);
      }
    } catch (e) { rec.error = String(e.message || e); }
    out.push(JSON.stringify(rec));
  }
  $("viewer-test").textContent = out.join("\n");
}
// "#viewer=<run_id>" opens that run and scrolls to the viewer.
// "?viewer=<run_id>" ("?viewer": the first run) opens it with the page above
// the viewer hidden, so the viewer is at the top unscrolled: headless
// screenshots come out blank once the page has scrolled.
const query = new URLSearchParams(location.search);
const wanted = location.hash.startsWith("#viewer=") ? location.hash.slice(8) : query.get("viewer") || "";
show(ids.includes(wanted) ? wanted : ids[0]);
if (query.has("viewer")) {
  for (const el of Array.from(document.body.children)) {
    if (el.id === "viewer-h") break;
    el.style.display = "none";
  }
} else if (location.hash.startsWith("#viewer")) {
  $("viewer-h").scrollIntoView();
}
if (testMode) {
  // A drag through the real handlers (the first run, shown above): pointer
  // down and up at (x, y) = (0.3, 0.4) of the original sphere's half-width
  // from its centre; the test checks the light and the environment's turn.
  const cv = $("v-orig"), b = cv.getBoundingClientRect(), x = 0.3, y = 0.4;
  cv.dispatchEvent(new PointerEvent("pointerdown", {clientX: b.left + (x + 1) / 2 * b.width, clientY: b.top + (1 - y) / 2 * b.height}));
  window.dispatchEvent(new PointerEvent("pointerup"));
  $("viewer-test").textContent += "\n" + JSON.stringify({drag: {run: state.id, x, y, light: state.light,
      env_rot: uniforms().env_rot, info: $("v-info").textContent, status: status.textContent}});
  // The phi_d slider moved to 30 deg through its handler: the approximation's
  // theta_h - theta_d slice (16 x 16) at the page's state then, and the
  // slice canvas's mean colour before and after (it must change).
  const phid = $("v-phid"), canvasMean = () => {
    const c = $("v-slice-approx"), d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
    let sum = 0;
    for (let k = 0; k < d.length; k += 4) sum += d[k] + d[k + 1] + d[k + 2];
    return sum / (d.length / 4 * 3);
  };
  const before = canvasMean();
  phid.value = "30";
  phid.dispatchEvent(new Event("input"));
  const sl = run(state.id, 1, 1, 16, 16, uniforms()), slice = [];
  for (let k = 0; k < 256; ++k) slice.push(sl[4 * k], sl[4 * k + 1], sl[4 * k + 2]);
  $("viewer-test").textContent += "\n" + JSON.stringify({phid: {run: state.id, phi_d: state.phi_d, slice,
      canvas_before: before, canvas_after: canvasMean(), label: $("v-phid-val").textContent, status: status.textContent}});
  // The checks below do not need the scene's lighting, and every handler
  // redraws the spheres (under SH lighting 512 nodes a pixel): point light.
  $("v-env").checked = false;
  $("v-env").dispatchEvent(new Event("change"));
  // The theta_i slider moved to 50 deg and the channel set to G through their
  // handlers: the Cartesian slices as plotted (data-series of their canvases),
  // and the albedo plot's curves.
  $("v-theta").value = "50";
  $("v-theta").dispatchEvent(new Event("input"));
  $("v-channel").value = "1";
  $("v-channel").dispatchEvent(new Event("change"));
  const series = (cid) => JSON.parse($(cid).dataset.series);
  $("viewer-test").textContent += "\n" + JSON.stringify({cart: {run: state.id, theta_i: state.theta_i, label: $("v-theta-val").textContent,
      in_plane: series("v-cart-in"), out_of_plane: series("v-cart-out"), albedo_plot: series("v-albedo"),
      albedo_note: $("v-albedo-note").textContent, status: status.textContent}});
  // Compare: the first two runs' approximations and the last run's original
  // ticked through their checkboxes' handlers, drawn at the scene's size
  // (theta_i back to 30 deg, the mean channel); A - B of the first two.
  $("v-theta").value = "30";
  $("v-theta").dispatchEvent(new Event("input"));
  $("v-channel").value = "mean";
  $("v-channel").dispatchEvent(new Event("change"));
  cmp.size = runs[ids[0]].scene.size;
  const boxes = Array.from(document.querySelectorAll("#v-cmp-list input"));
  const tick = (id, which) => {
    const box = boxes.find((el) => el.dataset.run === id && Number(el.dataset.which) === which);
    if (box) { box.checked = true; box.dispatchEvent(new Event("change")); }
  };
  if (ids.length >= 2) {
    tick(ids[0], 1);
    tick(ids[1], 1);
    tick(ids[ids.length - 1], 0);
    const rgb = (a) => { const v = []; for (let k = 0; k < a.length / 4; ++k) v.push(a[4 * k], a[4 * k + 1], a[4 * k + 2]); return v; };
    const last = cmp.last || {entries: [], spheres: [], diff: []};
    $("viewer-test").textContent += "\n" + JSON.stringify({compare: {entries: last.entries, size: cmp.size,
        spheres: last.spheres.map(rgb), diff: Array.from(last.diff), a: cmp.a, b: cmp.b, in_plane: series("v-cmp-in"),
        theta_i: state.theta_i, light: state.light, hidden: $("v-cmp-out").hidden,
        spheres_drawn: document.querySelectorAll("#v-cmp-spheres canvas").length, status: status.textContent}});
  }
  // The shape set to the torus through its handler: the first run's
  // approximation on it at the scene's size and light (no environment).
  $("v-shape").value = "torus";
  $("v-shape").dispatchEvent(new Event("change"));
  {
    const r = runs[ids[0]], n = r.scene.size;
    const a = run(ids[0], 0, 1, n, n, {light: r.scene.light, cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], theta_i: 0, phi_d: 0, shape: state.shape});
    const v = [], mask = [];
    for (let k = 0; k < n * n; ++k) { v.push(a[4 * k], a[4 * k + 1], a[4 * k + 2]); mask.push(a[4 * k + 3]); }
    $("viewer-test").textContent += "\n" + JSON.stringify({torus: {run: ids[0], size: n, radiance: v, mask, status: status.textContent,
        info: $("v-info").textContent}});
  }
  $("v-shape").value = "sphere";
  $("v-shape").dispatchEvent(new Event("change"));
  // "?hdr=PATH" (a file beside the page; Chromium needs
  // --allow-file-access-from-files): its bytes, read by a synchronous
  // XMLHttpRequest, go to loadHdrBytes, the function the file input's change
  // handler calls once its FileReader has the bytes (that asynchronous read
  // would race the headless DOM dump); then per run the approximation's
  // sphere under the map at the scene's size (environment not turned).
  const hdrPath = new URLSearchParams(location.search).get("hdr");
  if (hdrPath) {
    const xhr = new XMLHttpRequest();
    let bytes = null;
    try {
      xhr.open("GET", hdrPath, false);
      xhr.overrideMimeType("text/plain; charset=x-user-defined");
      xhr.send();
      const t = xhr.responseText;
      bytes = new Uint8Array(t.length);
      for (let k = 0; k < t.length; ++k) bytes[k] = t.charCodeAt(k) & 0xff;
    } catch (err) { status.textContent = "cannot read " + hdrPath + ": " + err.message; }
    if (bytes && bytes.length) loadHdrBytes(bytes, hdrPath.split("/").pop());
    const rec = {hdr: {status: status.textContent, info: $("v-info").textContent, loaded: !!state.hdr, runs: {}}};
    if (state.hdr)
      for (const id of ids) {
        const n = runs[id].scene.size, a = run(id, 0, 1, n, n, {light: runs[id].scene.light, cam: [1, 0, 0, 0, 1, 0, 0, 0, 1],
                                                                 theta_i: 0, phi_d: 0, env: true, hdr: state.hdr});
        const v = [];
        for (let k = 0; k < n * n; ++k) v.push(a[4 * k], a[4 * k + 1], a[4 * k + 2]);
        rec.hdr.runs[id] = v;
      }
    $("viewer-test").textContent += "\n" + JSON.stringify(rec);
  }
}
})();
