// The viewer's .hdr reader and band-limiting (experiments/report/viewer/hdr.js)
// run by Node outside the browser (CTest "docs: hdr.js reads RGBE and refuses
// malformed .hdr files"): flat and run-length scanlines decode to
// (m + 0.5) 2^(e - 136); every malformed file is refused with an Error naming
// the file and the line or scanline; the SH band-limiting reproduces a
// constant map and the map L = 1 + z exactly (to rounding) at order 2.
//   node tests/lint/hdr_test.js experiments/report/viewer/hdr.js
"use strict";
const fs = require("fs");
const vm = require("vm");
const box = {window: {}, Math, Float32Array, Float64Array, Uint8Array, Array, String, Number, Error, Object};
vm.runInNewContext(fs.readFileSync(process.argv[2], "utf8"), box);
const {parseHdr, bandLimited} = box.window.BF_HDR;
let failures = 0;
function check(ok, what) {
  if (!ok) { ++failures; console.log("FAILED: " + what); }
}
const enc = (s) => Array.from(s, (c) => c.charCodeAt(0));
const file = (header, pixels) => new Uint8Array([...enc(header), ...pixels]);
// 8 x 4 flat: texel (x, y) = RGBE (x + 1, y + 1, 7, 129).
const flat = [];
for (let y = 0; y < 4; ++y) for (let x = 0; x < 8; ++x) flat.push(x + 1, y + 1, 7, 129);
const head = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n";
{
  const m = parseHdr(file(head, flat), "flat.hdr");
  check(m.width === 8 && m.height === 4, "flat.hdr: 8 x 4");
  const v = m.data[3 * (2 * 8 + 5)], want = (6 + 0.5) * Math.pow(2, 129 - 136);
  check(Math.abs(v - want) < 1e-7, "flat.hdr: texel (5, 2) R = " + v + ", expected " + want);
}
// 16 x 8 run-length: each scanline 2 2 0 16, then per component a run of 16
// (count 144) of the value; R = y + 1, G = 3, B = 0, E = 130.
{
  const rle = [];
  for (let y = 0; y < 8; ++y) rle.push(2, 2, 0, 16, 144, y + 1, 144, 3, 144, 0, 144, 130);
  const m = parseHdr(file("#?RADIANCE\n\n-Y 8 +X 16\n", rle), "rle.hdr");
  const v = m.data[3 * (5 * 16 + 9)], g = m.data[3 * (5 * 16 + 9) + 1];
  check(Math.abs(v - 6.5 * Math.pow(2, -6)) < 1e-7 && Math.abs(g - 3.5 * Math.pow(2, -6)) < 1e-7,
        "rle.hdr: texel (9, 5) = " + v + ", " + g);
}
// Malformed files: the message names the file and where.
const bad = [
  ["magic.hdr", file("RADIANCE\n\n-Y 4 +X 8\n", flat), "magic.hdr: line 1: expected \"#?RADIANCE\""],
  ["format.hdr", file("#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 4 +X 8\n", flat), "format.hdr: line 2: expected FORMAT=32-bit_rle_rgbe"],
  ["res.hdr", file("#?RADIANCE\n\n+Y 4 +X 8\n", flat), "res.hdr: line 3: expected a resolution \"-Y H +X W\""],
  ["aspect.hdr", file("#?RADIANCE\n\n-Y 4 +X 12\n", flat), "aspect.hdr: expected a lat-long map W = 2 H, at least 8 x 4, found 12 x 4"],
  ["short.hdr", file(head, flat.slice(0, 4 * 8 * 3 + 5)), "short.hdr: scanline 3: expected more pixel data, found end of file"],
  ["eof.hdr", file("#?RADIANCE\nFORMAT=32-bit_rle_rgbe", []), "eof.hdr: line 2: expected a header line, found end of file"],
  ["run.hdr", file("#?RADIANCE\n\n-Y 4 +X 8\n", [2, 2, 0, 8, 140, 1]), "run.hdr: scanline 0: expected a run of 1..8 pixels, found 12"],
  ["width.hdr", file("#?RADIANCE\n\n-Y 4 +X 8\n", [2, 2, 0, 9, 136, 1]), "width.hdr: scanline 0: expected a run-length width of 8, found 9"],
];
for (const [name, bytes, want] of bad) {
  let msg = "";
  try { parseHdr(bytes, name); } catch (e) { msg = e.message; }
  check(msg.startsWith(want), name + ": message \"" + msg + "\", expected it to start with \"" + want + "\"");
}
// Band-limiting (64 x 32 map, order 2, on a 16 x 8 grid): a constant and
// L = 1 + z (degree 1) come back exactly.
{
  const W = 64, H = 32, data = new Float32Array(W * H * 3);
  for (let y = 0; y < H; ++y)
    for (let x = 0; x < W; ++x) {
      const z = Math.cos(Math.PI * (y + 0.5) / H);
      data.set([2, 1 + z, 0.5 + 0.25 * z], 3 * (y * W + x));
    }
  const g = bandLimited({width: W, height: H, data}, 2, 16);
  let worst = 0;
  for (let y = 0; y < 8; ++y)
    for (let x = 0; x < 16; ++x) {
      const z = Math.cos(Math.PI * (y + 0.5) / 8), want = [2, 1 + z, 0.5 + 0.25 * z];
      for (let c = 0; c < 3; ++c) worst = Math.max(worst, Math.abs(g[3 * (y * 16 + x) + c] - want[c]));
    }
  check(worst < 1e-5, "band-limited constant and 1 + z: worst error " + worst);
}
console.log(failures ? failures + " failed" : "hdr.js: all checks passed");
process.exit(failures ? 1 : 0);
