// The stress matrix (docs/design.md §7): hard cases (near-delta peaks, grazing-only
// samples, zeros, huge dynamic range, n = h, few samples, duplicates, untouched
// texels, thin projected data, rotated anisotropy, float extremes) run through
// the factorization methods, each result checked against the expectation
// written down with its case.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/sampleset.h"
#include "factor/homomorphic_fit.h"

namespace bf {

// What a (case, method) result must satisfy.
//  - Finite: no exception, every reconstructed value and metric finite.
//  - Bounded: Finite and rel_mse <= bound.
//  - Error: throws std::exception whose message contains `substring`.
//  - FiniteOrError: Finite, or an exception with a non-empty message (never a
//    NaN result); for cases where refusing is as good as answering.
struct StressExpectation {
  enum class Kind { Finite, Bounded, Error, FiniteOrError } kind = Kind::Finite;
  double bound = 0;       // Bounded: largest acceptable rel_mse
  std::string substring;  // Error: part of the expected message
  std::string to_string() const;  // "finite", "rel_mse<=0.5", "error~'mean'", "finite|error"
  // Parses the to_string() forms; throws std::invalid_argument otherwise.
  static StressExpectation parse(const std::string& s);
};

struct StressOptions {
  int res = 16;             // texture resolution of the homomorphic terms, 2..1024
  size_t samples = 4000;    // stratified samples per case (cases with their own count ignore it), >= 50
  int svd_res = 16;         // SVD texel grid resolution, 2..256
  uint64_t seed = 1;        // samples and random projections
  size_t cond_max_unknowns = 1200;  // dense condition estimate only up to this many unknowns
  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
};

// A case's inputs, built for given options.
struct StressInput {
  BrdfPtr brdf;     // the function sampled (the SVD tabulates it)
  SampleSet samples;
  int res = 16;     // texture resolution for this case (may override options.res)
};

struct StressCase {
  std::string name;         // e.g. "blinn-phong-n1e4"
  std::string description;  // one line
  std::function<StressInput(const StressOptions&)> make;
  StressExpectation expect;  // for every method unless overridden
  std::vector<std::pair<std::string, StressExpectation>> overrides;  // method -> expectation
  const StressExpectation& expectation(const std::string& method) const;
};

// The built-in case list.
std::vector<StressCase> stress_cases();
// Method names run on every case: "mccool" (McCool's two fixed projections,
// homomorphic fit), "random2" (two wiwo terms with fixed random orthonormal
// projections, solved jointly), "svd" (rank 2, linear), "svd-log" (rank 2, log).
std::vector<std::string> stress_methods();

struct StressResult {
  std::string case_name, method;
  bool threw = false;
  std::string message;      // exception text when threw
  bool finite = false;      // all reconstructed values and metrics finite
  double rel_mse = 0, cos_rmse = 0;  // NaN when threw
  // Homomorphic methods: max/min eigenvalue of the dense normal matrix of the
  // final joint solve (smoothing and gauge included, ridge excluded); Inf if
  // singular; NaN when not computed (SVD, or more than cond_max_unknowns).
  double condition = 0;
  size_t unknowns = 0;
  double seconds = 0;
  std::string expectation;
  bool pass = false;
};

// Runs one case through one method; never throws for the method's own errors
// (they are recorded), only for an unknown method name.
StressResult run_stress(const StressCase& c, const StressInput& in, const std::string& method,
                        const StressOptions& opt);

// Condition estimate of the normal matrix of solve_joint for `joint` on d
// (see StressResult::condition). Returns NaN when there are more than
// max_unknowns unknowns. unknowns (if given) receives their count.
double normal_matrix_condition(const FitData& d, const std::vector<TermSpec>& joint,
                               const FitOptions& opt, size_t max_unknowns,
                               size_t* unknowns = nullptr);

// "case,method,finite,rel_mse,cos_rmse,condition,unknowns,seconds,expectation,pass,message"
std::string stress_csv_header();
std::string stress_csv_row(const StressResult& r);

}  // namespace bf
