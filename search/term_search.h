// Cole's automatic factorization (thesis 2.2, 3.1, 4.1): greedy over terms;
// term j's projection is searched (Powell over quaternion pairs, or an nlopt
// optimizer over a local 6-parameter chart) with terms 1..j-1 kept, the
// objective being the rel_mse of the homomorphic fit with the last n terms
// solved jointly. Seeded random restarts run in parallel; the search runs at a
// small texture and the found projections are refitted at the final size.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "factor/homomorphic_fit.h"
#include "search/powell.h"

namespace bf {

struct SearchOptions {
  int terms = 2;                        // textures to build, >= 1
  Parameterization param = Parameterization::WiWo;
  int texture_size = 16;                // final texture resolution
  int search_texture_size = 0;          // resolution during the search; 0 = texture_size
  int restarts = 6;                     // seeded random starts per term, >= 0
  std::vector<std::string> guesses;     // extra starts: "wi", "wo", "wi+wo"
  bool reciprocity = false;             // every term read through its conjugate too
  FitOptions fit;                       // inner loop (solve_last = n, smoothing, eps)
  uint64_t seed = 1;
  // "powell" (Cole) or an nlopt algorithm: "praxis", "bobyqa", "neldermead",
  // "sbplx", "direct" (global, DIRECT-L), "crs" (global, CRS2 with local mutation).
  std::string optimizer = "powell";
  PowellOptions powell;                 // also: ftol and max_evaluations for nlopt
  int threads = 0;                      // restarts in parallel; 0 = hardware threads
  void validate() const;                // throws naming the field, value and rule
};

struct TermRecord {
  std::array<double, 8> rotation;  // quaternion pair [S; T], each [w, x, y, z]
  double search_rel_mse = 0;       // objective at the search resolution
  int evaluations = 0;             // inner-loop fits for this term (all starts)
  double seconds = 0;
  int best_start = 0;              // index of the winning start (restarts first, then guesses)
};

struct SearchResult {
  std::shared_ptr<HomomorphicFactorization> factorization;  // at texture_size
  std::vector<TermRecord> terms;
  std::vector<double> rel_mse_after_term;  // at texture_size, fit data
  int evaluations = 0;
  double seconds = 0;
};

SearchResult search_factorization(const FitData& data, const SearchOptions& opt);

// The objective of one candidate rotation for the next term (exposed for
// benchmarks and tests): rel_mse of fixed + joint with the candidate last.
class TermObjective {
 public:
  TermObjective(const FitData& data, const std::vector<FactorTerm>& fixed,
                std::vector<TermSpec> joint_known, const SearchOptions& opt, int res);
  double operator()(const Rotation4& r) const;
  TermSpec spec(const Rotation4& r) const;
  const std::array<std::vector<double>, 3>& fixed_values() const { return fixed_values_; }
  const std::vector<TermSpec>& joint_known() const { return joint_known_; }

 private:
  const FitData& data_;
  std::array<std::vector<double>, 3> fixed_values_;
  std::vector<TermSpec> joint_known_;
  const SearchOptions& opt_;
  int res_;
};

}  // namespace bf
