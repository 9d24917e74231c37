// Line plots on a 2D canvas for report.html's viewer (window.BF_PLOT): axes
// with ticks, several series with a legend, a log or linear y axis, and an
// optional shaded band (the albedo > 1 region). Each call also stores what it
// drew in the canvas's data-series attribute (JSON: x, y and label of every
// series), so a test reads the plotted numbers from a DOM dump.
window.BF_PLOT = (function () {
  "use strict";
  const COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"];
  function fmt(v) {
    return Math.abs(v) >= 1e4 || (Math.abs(v) < 1e-3 && v !== 0) ? v.toExponential(1) : (+v.toPrecision(3)).toString();
  }
  // opts: {xmin, xmax, xlabel, ylabel, log, ymin (log only, else 0), ymax,
  //        band: {y0, y1, colour, label} (optional), xticks: [..]}
  // series: [{x: [..], y: [..], label, colour?, dash?}]
  function linePlot(cv, series, opts) {
    const ctx = cv.getContext("2d"), W = cv.width, H = cv.height;
    ctx.font = "11px sans-serif";
    // The legend in two columns when every label fits in half the width, else one.
    const cols = series.every((s) => ctx.measureText(s.label).width + 30 < (W - 52) / 2) ? 2 : 1;
    const L = 52, R = 8, T = 8, B = 34 + 14 * Math.ceil(series.length / cols);
    ctx.clearRect(0, 0, W, H);
    ctx.fillStyle = "#fff";
    ctx.fillRect(0, 0, W, H);
    const ymin = opts.log ? opts.ymin : 0;
    let ymax = opts.ymax;
    if (!(ymax > ymin)) ymax = ymin > 0 ? ymin * 10 : 1;
    const X = (x) => L + (W - L - R) * (x - opts.xmin) / (opts.xmax - opts.xmin);
    const Y = (y) => {
      const t = opts.log ? (Math.log10(Math.max(y, ymin)) - Math.log10(ymin)) / (Math.log10(ymax) - Math.log10(ymin))
                         : (y - ymin) / (ymax - ymin);
      return T + (H - T - B) * (1 - Math.min(1.02, Math.max(-0.02, t)));
    };
    if (opts.band && opts.band.y1 > opts.band.y0) {
      const y0 = Math.max(opts.band.y0, ymin), y1 = Math.min(opts.band.y1, ymax);
      if (y1 > y0) {
        ctx.fillStyle = opts.band.colour;
        ctx.fillRect(L, Y(y1), W - L - R, Y(y0) - Y(y1));
      }
    }
    ctx.strokeStyle = "#999";
    ctx.lineWidth = 1;
    ctx.strokeRect(L, T, W - L - R, H - T - B);
    ctx.fillStyle = "#222";
    ctx.font = "11px sans-serif";
    ctx.textAlign = "center";
    for (const x of opts.xticks) {
      ctx.fillText(String(x), X(x), H - B + 13);
      ctx.beginPath(); ctx.moveTo(X(x), H - B); ctx.lineTo(X(x), H - B + 3); ctx.stroke();
    }
    ctx.fillText(opts.xlabel, L + (W - L - R) / 2, H - B + 26);
    ctx.textAlign = "right";
    const yt = [];
    if (opts.log) {
      for (let e = Math.ceil(Math.log10(ymin)); e <= Math.log10(ymax); ++e) yt.push(Math.pow(10, e));
    } else {
      for (let k = 0; k <= 4; ++k) yt.push(ymin + (ymax - ymin) * k / 4);
    }
    for (const y of yt) {
      ctx.fillText(fmt(y), L - 4, Y(y) + 4);
      ctx.beginPath(); ctx.moveTo(L - 3, Y(y)); ctx.lineTo(L, Y(y)); ctx.stroke();
    }
    ctx.save();
    ctx.translate(11, T + (H - T - B) / 2);
    ctx.rotate(-Math.PI / 2);
    ctx.textAlign = "center";
    ctx.fillText(opts.ylabel, 0, 0);
    ctx.restore();
    ctx.save();
    ctx.beginPath();
    ctx.rect(L, T, W - L - R, H - T - B);
    ctx.clip();
    series.forEach((s, i) => {
      ctx.strokeStyle = s.colour || COLOURS[i % COLOURS.length];
      ctx.setLineDash(s.dash || []);
      ctx.lineWidth = 1.5;
      ctx.beginPath();
      s.x.forEach((x, k) => { if (k) ctx.lineTo(X(x), Y(s.y[k])); else ctx.moveTo(X(x), Y(s.y[k])); });
      ctx.stroke();
    });
    ctx.restore();
    // Legend: two columns below the axis label.
    ctx.textAlign = "left";
    series.forEach((s, i) => {
      const x = L + (i % cols) * (W - L) / 2, y = H - B + 40 + 14 * Math.floor(i / cols);
      ctx.strokeStyle = s.colour || COLOURS[i % COLOURS.length];
      ctx.setLineDash(s.dash || []);
      ctx.beginPath(); ctx.moveTo(x, y - 4); ctx.lineTo(x + 22, y - 4); ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillText(s.label, x + 26, y);
    });
    cv.dataset.series = JSON.stringify(series.map((s) => ({label: s.label, x: s.x, y: s.y})));
  }
  return {linePlot, fmt, COLOURS};
})();
