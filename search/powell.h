// Powell's direction-set minimization over 4D rotations (thesis 3.1.1-3.1.2):
// lines R(t) = D^t R_s, golden-section (or Brent) line minimization with
// bracketing over the periodic t, Cole's six initial directions, and the Numerical Recipes rule
// for replacing a direction by the sweep's net direction.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "search/rotation4.h"

namespace bf {

using RotationObjective = std::function<double(const Rotation4&)>;

// Brent's final bracket as a fraction of PowellOptions::line_tol. Brent's
// parabolic steps make a narrow bracket cheap (fewer fits than the golden
// section even at a quarter of its width), and at the golden section's width
// its searches end worse on more terms (docs/speed.md, "The line search").
constexpr double kBrentBracketFraction = 0.25;

struct PowellOptions {
  // Stop when a full sweep improves less than this, relatively:
  // 2 (f0 - fN) <= ftol (|f0| + |fN|) + 1e-20.
  double ftol = 1e-3;
  double line_tol = 0.02;     // golden section stops when the bracket is narrower (t, radians)
  // Refinement of a bracketed line minimum: Golden (golden section, the
  // original, to a bracket line_tol wide) or Brent (Brent's parabolic
  // interpolation with golden-section safeguard, to a bracket
  // kBrentBracketFraction * line_tol wide: tighter than the golden section's
  // and still fewer evaluations; docs/speed.md).
  enum class LineSearch { Golden, Brent } line_search = LineSearch::Golden;
  double initial_step = 0.3;  // first bracketing step along t
  int max_sweeps = 30;        // >= 1
  int max_evaluations = 5000; // objective evaluations per minimization, >= 10
  void validate() const;      // throws std::invalid_argument naming the field
};

// "golden" / "brent" <-> LineSearch; parse throws std::invalid_argument naming
// the field, the expected names and what was found.
PowellOptions::LineSearch parse_line_search(const std::string& name);
std::string to_string(PowellOptions::LineSearch ls);

struct PowellResult {
  Rotation4 best;
  double value = 0;
  int evaluations = 0;
  int sweeps = 0;
};

// Minimizes f from start. Never returns a point worse than start.
PowellResult powell_minimize(const RotationObjective& f, const Rotation4& start,
                             const PowellOptions& opt);

// The same search over several rotations at once (f of all of them): Cole's
// six directions for each rotation in turn, the others held, and the sweep's
// net direction moving all of them together (each rotation's part scaled by
// one common factor, so the line passes through the sweep's end point). With
// one rotation it is powell_minimize, step for step.
using JointRotationObjective = std::function<double(const std::vector<Rotation4>&)>;
struct JointPowellResult {
  std::vector<Rotation4> best;
  double value = 0;
  int evaluations = 0;
  int sweeps = 0;
};
JointPowellResult powell_minimize_joint(const JointRotationObjective& f, const std::vector<Rotation4>& start,
                                        const PowellOptions& opt);

// The line search on a function of t alone: g(0) = f0 is known, g is
// evaluated elsewhere as needed (the caller counts). Bracketing from
// opt.initial_step, then opt.line_search's refinement. Returns the best value
// found (never above f0, never above any value it evaluated) and its t.
using LineFunction = std::function<double(double)>;
double line_minimize_1d(const LineFunction& g, double f0, const PowellOptions& opt, double* best_t);

// One line minimization along dir from start (f(start) = f0 known).
// Returns the best t found and its value; counts evaluations into *evals.
double line_minimize(const RotationObjective& f, const Rotation4& start, double f0,
                     const LineDirection& dir, const PowellOptions& opt, double* best_t,
                     int* evals);

}  // namespace bf
