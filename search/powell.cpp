// Powell direction-set search over quaternion pairs (see powell.h).
#include "search/powell.h"
#include "solvers/option_error.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace bf {

void PowellOptions::validate() const {
  if (!(ftol > 0)) throw OptionError("ftol", "ftol: expected > 0, found " + std::to_string(ftol));
  if (!(line_tol > 0))
    throw OptionError("line_tol", "line_tol: expected > 0, found " + std::to_string(line_tol));
  if (!(initial_step > 0 && initial_step < 2 * M_PI))
    throw OptionError("initial_step", "initial_step: expected in (0, 2 pi), found " +
                                std::to_string(initial_step));
  if (max_sweeps < 1)
    throw OptionError("max_sweeps", "max_sweeps: expected >= 1, found " + std::to_string(max_sweeps));
  if (max_evaluations < 10)
    throw OptionError("max_evaluations", "max_evaluations: expected >= 10, found " +
                                std::to_string(max_evaluations));
}

PowellOptions::LineSearch parse_line_search(const std::string& name) {
  if (name == "golden") return PowellOptions::LineSearch::Golden;
  if (name == "brent") return PowellOptions::LineSearch::Brent;
  throw OptionError("line_search", "line_search: expected \"golden\" or \"brent\", found \"" + name + "\"");
}

std::string to_string(PowellOptions::LineSearch ls) {
  return ls == PowellOptions::LineSearch::Brent ? "brent" : "golden";
}

namespace {

// Brent's method on the bracket [lo, hi] around x (fx <= the values at lo and
// hi, which are flo and fhi): parabolic steps through the three best points
// so far, a golden-section step whenever the parabola's step is outside the
// bracket or does not shrink fast enough (more than half the step before
// last). Stops when x is within the tolerance of the bracket's middle, i.e.
// the bracket is about `width` wide (the caller passes
// kBrentBracketFraction * line_tol). The first
// parabola goes through the bracket itself, so it costs no extra evaluation.
double brent_refine(const LineFunction& g, double lo, double flo, double x, double fx, double hi, double fhi,
                    double width, double* best_t) {
  constexpr double kCGold = 0.3819660112501051;  // 1 - 1/golden ratio
  const double tol = 0.25 * width;
  double a = lo, b = hi;
  // w: second best point, v: third best (the previous w).
  double w = flo <= fhi ? lo : hi, fw = std::min(flo, fhi);
  double v = flo <= fhi ? hi : lo, fv = std::max(flo, fhi);
  double d = 0.0, e = b - a;  // this step and the one before last
  for (int it = 0; it < 200; ++it) {
    const double xm = 0.5 * (a + b);
    if (std::abs(x - xm) <= 2 * tol - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol) {
      // Vertex of the parabola through (x, fx), (w, fw), (v, fv) as x + p / q.
      const double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2.0 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      const double e_before = e;
      e = d;
      if (std::abs(p) < std::abs(0.5 * q * e_before) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < 2 * tol || b - u < 2 * tol) d = std::copysign(tol, xm - x);
        golden = false;
      }
    }
    if (golden) {
      e = x >= xm ? a - x : b - x;
      d = kCGold * e;
    }
    const double u = std::abs(d) >= tol ? x + d : x + std::copysign(tol, d);
    const double fu = g(u);
    if (fu <= fx) {
      (u >= x ? a : b) = x;
      v = w; fv = fw;
      w = x; fw = fx;
      x = u; fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w; fv = fw;
        w = u; fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u; fv = fu;
      }
    }
  }
  *best_t = x;
  return fx;
}

}  // namespace

double line_minimize_1d(const LineFunction& g, double f0, const PowellOptions& opt, double* best_t) {
  constexpr double kGold = 1.618033988749895;
  constexpr double kR = 0.6180339887498949;  // 1 / golden ratio
  const double kMaxT = 2 * M_PI;             // half the 4 pi period on either side
  *best_t = 0.0;

  // Bracket (a, b, c) with g(b) <= g(a), g(b) <= g(c), starting at t = 0.
  double a = 0.0, fa = f0;
  double b = opt.initial_step, fb = g(b);
  if (fb > fa) {
    const double bm = -opt.initial_step, fbm = g(bm);
    if (fbm >= fa) {
      // (bm, 0, b) already brackets a minimum at the start.
      if (opt.line_search == PowellOptions::LineSearch::Brent)
        return brent_refine(g, bm, fbm, 0.0, f0, b, fb, kBrentBracketFraction * opt.line_tol, best_t);
      double lo = bm, hi = b, x1, x2, f1, f2;
      x1 = hi - kR * (hi - lo);
      x2 = lo + kR * (hi - lo);
      f1 = g(x1);
      f2 = g(x2);
      double bt = 0.0, bv = f0;
      while (hi - lo > opt.line_tol) {
        if (f1 < f2) {
          hi = x2; x2 = x1; f2 = f1; x1 = hi - kR * (hi - lo); f1 = g(x1);
        } else {
          lo = x1; x1 = x2; f1 = f2; x2 = lo + kR * (hi - lo); f2 = g(x2);
        }
      }
      for (auto [x, v] : {std::pair{x1, f1}, std::pair{x2, f2}})
        if (v < bv) { bv = v; bt = x; }
      *best_t = bt;
      return bv;
    }
    b = bm;
    fb = fbm;
  }
  // Downhill from a to b: expand until the function rises or |t| hits the period bound.
  double c = b + kGold * (b - a), fc;
  if (std::abs(c) > kMaxT) c = std::copysign(kMaxT, c);
  fc = g(c);
  while (fc < fb && std::abs(c) < kMaxT) {
    a = b; fa = fb;
    b = c; fb = fc;
    c = b + kGold * (b - a);
    if (std::abs(c) > kMaxT) c = std::copysign(kMaxT, c);
    fc = g(c);
  }
  if (fc < fb) {  // no rise before the bound: the bound is the best we have
    *best_t = c;
    return fc;
  }
  if (opt.line_search == PowellOptions::LineSearch::Brent) {
    double bt;
    const double bv = a < c ? brent_refine(g, a, fa, b, fb, c, fc, kBrentBracketFraction * opt.line_tol, &bt)
                            : brent_refine(g, c, fc, b, fb, a, fa, kBrentBracketFraction * opt.line_tol, &bt);
    // Never worse than the start (a = 0 unless the bracket moved on).
    if (f0 <= bv) {
      *best_t = 0.0;
      return f0;
    }
    *best_t = bt;
    return bv;
  }
  // Golden-section search inside [min(a,c), max(a,c)] around b.
  double lo = std::min(a, c), hi = std::max(a, c);
  double x1, x2, f1, f2;
  if (hi - b > b - lo) {
    x1 = b; f1 = fb; x2 = b + (1 - kR) * (hi - b); f2 = g(x2);
  } else {
    x2 = b; f2 = fb; x1 = b - (1 - kR) * (b - lo); f1 = g(x1);
  }
  while (hi - lo > opt.line_tol) {
    if (f2 < f1) {
      lo = x1; x1 = x2; f1 = f2; x2 = kR * x1 + (1 - kR) * hi; f2 = g(x2);
    } else {
      hi = x2; x2 = x1; f2 = f1; x1 = kR * x2 + (1 - kR) * lo; f1 = g(x1);
    }
  }
  double bt = b, bv = fb;
  if (f1 < bv) { bv = f1; bt = x1; }
  if (f2 < bv) { bv = f2; bt = x2; }
  if (f0 <= bv) { bt = 0.0; bv = f0; }
  *best_t = bt;
  return bv;
}

namespace {

// A line through several rotations: one LineDirection per rotation (zero for
// a rotation the line holds).
using JointDirection = std::vector<LineDirection>;

// The line's point at t; a new point of the search is renormalized, a point
// the line search only evaluates is not.
std::vector<Rotation4> joint_at(const JointDirection& dir, const std::vector<Rotation4>& start, double t,
                                bool normalize) {
  std::vector<Rotation4> out(start.size());
  for (size_t i = 0; i < start.size(); ++i) {
    if (dir[i].is_zero()) {
      out[i] = start[i];
      continue;
    }
    out[i] = dir[i].at(start[i], t);
    if (normalize) out[i] = out[i].normalized();
  }
  return out;
}

double joint_line_minimize(const JointRotationObjective& f, const std::vector<Rotation4>& start, double f0,
                           const JointDirection& dir, const PowellOptions& opt, double* best_t, int* evals) {
  *best_t = 0.0;
  if (std::all_of(dir.begin(), dir.end(), [](const LineDirection& d) { return d.is_zero(); })) return f0;
  return line_minimize_1d(
      [&](double t) {
        ++*evals;
        return f(joint_at(dir, start, t, false));
      },
      f0, opt, best_t);
}

// The net direction of a sweep, D_i = p_i p0_i^-1 for each rotation, as a
// line: all rates scaled by the one factor that makes the fastest advance at
// 1/2 radian per unit t (LineDirection::from's convention).
JointDirection net_direction(const std::vector<Rotation4>& D) {
  JointDirection d(D.size());
  double m = 0;
  for (size_t i = 0; i < D.size(); ++i) {
    d[i] = LineDirection::unscaled(D[i]);
    m = std::max(m, d[i].rate());
  }
  if (m < 1e-300) return JointDirection(D.size());
  for (LineDirection& di : d) {
    di.logS *= 0.5 / m;
    di.logT *= 0.5 / m;
  }
  return d;
}

}  // namespace

double line_minimize(const RotationObjective& f, const Rotation4& start, double f0,
                     const LineDirection& dir, const PowellOptions& opt, double* best_t,
                     int* evals) {
  return joint_line_minimize([&](const std::vector<Rotation4>& R) { return f(R[0]); }, {start}, f0, {dir}, opt,
                             best_t, evals);
}

JointPowellResult powell_minimize_joint(const JointRotationObjective& f, const std::vector<Rotation4>& start,
                                        const PowellOptions& opt) {
  opt.validate();
  if (start.empty()) throw std::invalid_argument("powell_minimize_joint: expected at least one rotation, found 0");
  const size_t J = start.size();
  JointPowellResult res;
  std::vector<JointDirection> dirs;
  for (size_t i = 0; i < J; ++i)
    for (const Rotation4& d : cole_basis_directions()) {
      JointDirection dir(J);
      dir[i] = LineDirection::from(d);
      dirs.push_back(std::move(dir));
    }
  std::vector<Rotation4> p(J);
  for (size_t i = 0; i < J; ++i) p[i] = start[i].normalized();
  double fp = f(p);
  res.evaluations = 1;
  for (int sweep = 0; sweep < opt.max_sweeps && res.evaluations < opt.max_evaluations; ++sweep) {
    res.sweeps = sweep + 1;
    const std::vector<Rotation4> p0 = p;
    const double f0 = fp;
    int ibig = 0;
    double del = 0.0;
    for (size_t i = 0; i < dirs.size(); ++i) {
      double t;
      const double fnew = joint_line_minimize(f, p, fp, dirs[i], opt, &t, &res.evaluations);
      if (fp - fnew > del) {
        del = fp - fnew;
        ibig = static_cast<int>(i);
      }
      if (fnew < fp) {
        p = joint_at(dirs[i], p, t, true);
        fp = fnew;
      }
    }
    if (2.0 * (f0 - fp) <= opt.ftol * (std::abs(f0) + std::abs(fp)) + 1e-20) break;
    // Net direction of the sweep, D = R_f R_s^-1, and the extrapolated point D R_f.
    std::vector<Rotation4> D(J), pe(J);
    for (size_t i = 0; i < J; ++i) {
      D[i] = p[i].compose(p0[i].inverse()).normalized();
      pe[i] = D[i].compose(p[i]).normalized();
    }
    const double fe = f(pe);
    ++res.evaluations;
    if (fe < f0) {
      const double tt = 2.0 * (f0 - 2.0 * fp + fe) * std::pow(f0 - fp - del, 2) -
                        del * std::pow(f0 - fe, 2);
      if (tt < 0.0) {
        const JointDirection nd = net_direction(D);
        double t;
        const double fnew = joint_line_minimize(f, p, fp, nd, opt, &t, &res.evaluations);
        if (fnew < fp) {
          p = joint_at(nd, p, t, true);
          fp = fnew;
        }
        dirs[ibig] = dirs.back();
        dirs.back() = nd;
      }
    }
  }
  res.best = p;
  res.value = fp;
  return res;
}

PowellResult powell_minimize(const RotationObjective& f, const Rotation4& start, const PowellOptions& opt) {
  const JointPowellResult r =
      powell_minimize_joint([&](const std::vector<Rotation4>& R) { return f(R[0]); }, {start}, opt);
  PowellResult res;
  res.best = r.best[0];
  res.value = r.value;
  res.evaluations = r.evaluations;
  res.sweeps = r.sweeps;
  return res;
}

}  // namespace bf
