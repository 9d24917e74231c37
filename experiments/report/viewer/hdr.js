// Environment maps for report.html's viewer (window.BF_HDR): a Radiance .hdr
// (RGBE) reader, and the band-limited lighting the page shades with, made the
// way the toolkit makes it (factor/lighting.h): the lat-long map projected
// onto orthonormal real spherical harmonics up to order L with Fejer weights
// in theta and the uniform rule in phi (project_latlong), the series
// evaluated on a 128 x 64 lat-long grid (as viewer.js's scene lighting), and
// LitShader's hemisphere rule (Gauss-Legendre max(16, L + 8) in cos theta
// times twice as many phi).
window.BF_HDR = (function () {
  "use strict";
  // Parses a Radiance .hdr: "#?" magic, header lines up to an empty line
  // (FORMAT, when given, must be 32-bit_rle_rgbe), "-Y H +X W", then H
  // scanlines, each flat RGBE or new-style run-length encoded (2 2 W/256
  // W%256, then per component runs: count > 128 repeats the next byte
  // count - 128 times, else count literal bytes). Component = (m + 0.5)
  // 2^(e - 136), 0 when e = 0. Throws an Error naming `name` and where.
  function parseHdr(bytes, name) {
    let pos = 0, lineNo = 0;
    const fail = (what) => { throw new Error(name + ": " + what); };
    const line = () => {
      const start = pos;
      while (pos < bytes.length && bytes[pos] !== 10) ++pos;
      if (pos >= bytes.length) fail("line " + (lineNo + 1) + ": expected a header line, found end of file");
      ++lineNo;
      return String.fromCharCode(...bytes.subarray(start, pos++));
    };
    const magic = line();
    if (!magic.startsWith("#?")) fail("line 1: expected \"#?RADIANCE\", found \"" + magic.slice(0, 40) + "\"");
    for (;;) {
      const s = line();
      if (s === "") break;
      if (s.startsWith("FORMAT=") && s !== "FORMAT=32-bit_rle_rgbe") fail("line " + lineNo + ": expected FORMAT=32-bit_rle_rgbe, found " + s.slice(0, 60));
    }
    const res = line(), m = /^-Y (\d+) \+X (\d+)$/.exec(res);
    if (!m) fail("line " + lineNo + ": expected a resolution \"-Y H +X W\", found \"" + res.slice(0, 60) + "\"");
    const h = Number(m[1]), w = Number(m[2]);
    if (!(w >= 8 && h >= 4 && w === 2 * h)) fail("expected a lat-long map W = 2 H, at least 8 x 4, found " + w + " x " + h);
    if (w * h > 1 << 24) fail("expected at most 16M pixels, found " + w + " x " + h);
    const out = new Float32Array(w * h * 3), scan = new Uint8Array(w * 4);
    for (let y = 0; y < h; ++y) {
      const need = (n) => { if (bytes.length - pos < n) fail("scanline " + y + ": expected more pixel data, found end of file"); };
      if (w >= 8 && w < 32768 && bytes.length - pos >= 4 && bytes[pos] === 2 && bytes[pos + 1] === 2 && !(bytes[pos + 2] & 0x80)) {
        const rw = bytes[pos + 2] << 8 | bytes[pos + 3];
        if (rw !== w) fail("scanline " + y + ": expected a run-length width of " + w + ", found " + rw);
        pos += 4;
        for (let c = 0; c < 4; ++c)
          for (let x = 0; x < w;) {
            need(1);
            let count = bytes[pos++];
            const run = count > 128;
            if (run) count -= 128;
            if (count === 0 || x + count > w) fail("scanline " + y + ": expected a run of 1.." + (w - x) + " pixels, found " + count);
            need(run ? 1 : count);
            for (let k = 0; k < count; ++k) scan[4 * (x + k) + c] = run ? bytes[pos] : bytes[pos + k];
            pos += run ? 1 : count;
            x += count;
          }
      } else {
        need(4 * w);
        scan.set(bytes.subarray(pos, pos + 4 * w));
        pos += 4 * w;
      }
      for (let x = 0; x < w; ++x) {
        const e = scan[4 * x + 3], o = 3 * (y * w + x);
        for (let c = 0; c < 3; ++c) out[o + c] = e === 0 ? 0 : (scan[4 * x + c] + 0.5) * Math.pow(2, e - 136);
      }
    }
    return {width: w, height: h, data: out};
  }
  // Fejer's first rule on theta_j = pi (j + 1/2) / n (weights for dz).
  function fejer(n) {
    const w = [];
    for (let j = 0; j < n; ++j) {
      const th = Math.PI * (j + 0.5) / n;
      let s = 0;
      for (let k = 1; k <= n / 2; ++k) s += Math.cos(2 * k * th) / (4 * k * k - 1);
      w.push(2 / n * (1 - 2 * s));
    }
    return w;
  }
  // Normalized associated Legendre K_lm P_lm(z), m = 0..l <= L, index
  // l (l + 1) / 2 + m, with K_lm = sqrt((2l+1)/(4 pi) (l-m)!/(l+m)!) and the
  // sqrt(2) of the real basis folded in for m > 0.
  function legendre(L, z) {
    const p = new Float64Array((L + 1) * (L + 2) / 2), s = Math.sqrt(Math.max(0, 1 - z * z));
    const idx = (l, m) => l * (l + 1) / 2 + m;
    let pmm = 1;
    for (let m = 0; m <= L; ++m) {
      if (m > 0) pmm *= -(2 * m - 1) * s;
      p[idx(m, m)] = pmm;
      if (m < L) p[idx(m + 1, m)] = z * (2 * m + 1) * pmm;
      for (let l = m + 2; l <= L; ++l) p[idx(l, m)] = ((2 * l - 1) * z * p[idx(l - 1, m)] - (l + m - 1) * p[idx(l - 2, m)]) / (l - m);
    }
    for (let l = 0; l <= L; ++l)
      for (let m = 0; m <= l; ++m) {
        let r = (2 * l + 1) / (4 * Math.PI);
        for (let k = l - m + 1; k <= l + m; ++k) r /= k;
        p[idx(l, m)] *= Math.sqrt(r) * (m > 0 ? Math.SQRT2 : 1);
      }
    return p;
  }
  // Coefficients per channel: c[ch][l][m + l] for the basis P(cos theta)
  // cos(m phi) (m >= 0) and P sin(|m| phi) (m < 0); separable sums per row.
  function project(map, L) {
    const {width: W, height: H, data} = map, wz = fejer(H), dphi = 2 * Math.PI / W;
    const c = [0, 1, 2].map(() => Array.from({length: L + 1}, (_, l) => new Float64Array(2 * l + 1)));
    const cs = [], sn = [];
    for (let x = 0; x < W; ++x) {
      const ph = dphi * (x + 0.5);
      cs.push(Array.from({length: L + 1}, (_, m) => Math.cos(m * ph)));
      sn.push(Array.from({length: L + 1}, (_, m) => Math.sin(m * ph)));
    }
    for (let y = 0; y < H; ++y) {
      const p = legendre(L, Math.cos(Math.PI * (y + 0.5) / H)), row = [0, 1, 2].map(() => ({a: new Float64Array(L + 1), b: new Float64Array(L + 1)}));
      for (let x = 0; x < W; ++x)
        for (let ch = 0; ch < 3; ++ch) {
          const v = data[3 * (y * W + x) + ch];
          if (v === 0) continue;
          for (let m = 0; m <= L; ++m) { row[ch].a[m] += v * cs[x][m]; row[ch].b[m] += v * sn[x][m]; }
        }
      for (let ch = 0; ch < 3; ++ch)
        for (let l = 0; l <= L; ++l)
          for (let m = 0; m <= l; ++m) {
            const q = p[l * (l + 1) / 2 + m] * wz[y] * dphi;
            c[ch][l][l + m] += q * row[ch].a[m];
            if (m > 0) c[ch][l][l - m] += q * row[ch].b[m];
          }
    }
    return c;
  }
  function radiance(c, L, w) {
    const p = legendre(L, w[2]), ph = Math.atan2(w[1], w[0]), out = [0, 0, 0];
    for (let l = 0; l <= L; ++l)
      for (let m = 0; m <= l; ++m) {
        const q = p[l * (l + 1) / 2 + m], cm = Math.cos(m * ph), sm = Math.sin(m * ph);
        for (let ch = 0; ch < 3; ++ch) out[ch] += q * (c[ch][l][l + m] * cm + (m > 0 ? c[ch][l][l - m] * sm : 0));
      }
    return out;
  }
  // The band-limited lighting of `map` at order L on a W x W/2 lat-long grid
  // (texel centres, row 0 at theta = 0), RGB floats.
  function bandLimited(map, L, W) {
    const c = project(map, L), H = W / 2, out = new Float32Array(W * H * 3);
    for (let y = 0; y < H; ++y)
      for (let x = 0; x < W; ++x) {
        const th = Math.PI * (y + 0.5) / H, ph = 2 * Math.PI * (x + 0.5) / W;
        const v = radiance(c, L, [Math.sin(th) * Math.cos(ph), Math.sin(th) * Math.sin(ph), Math.cos(th)]);
        out.set(v, 3 * (y * W + x));
      }
    return out;
  }
  return {parseHdr, bandLimited};
})();
