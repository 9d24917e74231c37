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
  s.units.forEach((t, k) => {
    gl.activeTexture(gl.TEXTURE0 + k);
    gl.bindTexture(gl.TEXTURE_2D, t.tex);
    gl.uniform1i(gl.getUniformLocation(s.prog, t.name), k);
  });
  const L = (n) => gl.getUniformLocation(s.prog, n);
  gl.uniform1i(L("u_mode"), mode);
  gl.uniform1i(L("u_which"), which);
  gl.uniform2f(L("u_size"), w, h);
  gl.uniform3fv(L("u_light"), u.light);
  gl.uniform1f(L("u_intensity"), r.scene.intensity);
  gl.uniformMatrix3fv(L("u_cam"), false, u.cam);
  gl.uniform1f(L("u_theta_i"), u.theta_i);
  gl.uniform1f(L("u_phi_d"), u.phi_d);
  gl.uniform1i(L("u_env"), u.env && r.environment ? 1 : 0);
  gl.uniform1i(L("u_rule_n"), r.environment ? r.environment.nodes : 0);
  // u.env_rot is R row-major; read as column-major it is R^T, the lookup matrix.
  gl.uniformMatrix3fv(L("u_env_rot"), false, u.env_rot || [1, 0, 0, 0, 1, 0, 0, 0, 1]);
  gl.drawArrays(gl.TRIANGLES, 0, 3);
  const px = new Float32Array(w * h * 4);
  gl.readPixels(0, 0, w, h, gl.RGBA, gl.FLOAT, px);
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
               theta_i: 30 * Math.PI / 180, phi_d: Math.PI / 2, env: true, channel: "mean", log: true};
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
          env_rot: envRotation(state.light)};
}
function draw() {
  const id = state.id, r = runs[id], n = 160;
  const u = uniforms();
  let A, B;
  try {
    A = run(id, 0, 0, n, n, u);
    B = run(id, 0, 1, n, n, u);
  } catch (e) { status.textContent = "shader error: " + e.message; return; }
  const expo = r.exposure * state.exposure;
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
  $("v-info").textContent = r.label + " (" + r.method + "), " +
      (state.env && r.environment ? "lit by the scene's SH lighting (" + r.environment.nodes + " hemisphere nodes per pixel), turned " +
                                    Math.round(Math.acos(Math.min(1, Math.max(-1, (u.env_rot[0] + u.env_rot[4] + u.env_rot[8] - 1) / 2))) * 180 / Math.PI) +
                                    " deg with the light"
                                  : "point light (" + state.light.map((v) => v.toFixed(2)).join(", ") + ")") +
      ", view yaw " + Math.round(state.yaw * 180 / Math.PI) + " pitch " + Math.round(state.pitch * 180 / Math.PI) + " deg";
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
    $("v-env").disabled = !runs[id].environment;
    draw();
    status.textContent = "";
  });
}
sel.onchange = () => show(sel.value);
$("v-env").onchange = (e) => { state.env = e.target.checked; draw(); };
$("v-exposure").oninput = (e) => { state.exposure = Math.pow(2, +e.target.value); draw(); };
$("v-theta").oninput = (e) => { state.theta_i = +e.target.value * Math.PI / 180; draw(); };
$("v-phid").oninput = (e) => {
  state.phi_d = +e.target.value * Math.PI / 180;
  $("v-phid-val").textContent = e.target.value;
  draw();
};
$("v-channel").onchange = (e) => { state.channel = e.target.value; draw(); };
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
}
})();
