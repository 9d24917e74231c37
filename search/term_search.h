// Cole's automatic factorization (thesis 2.2, 3.1, 4.1): greedy over terms;
// term j's projection is searched (Powell over quaternion pairs, or an nlopt
// optimizer over a local 6-parameter chart) with terms 1..j-1 kept, the
// objective being the rel_mse of the homomorphic fit with the last n terms
// solved jointly. Seeded random restarts run in parallel; the search runs at a
// small texture and the found projections are refitted at the final size.
//
// Two non-greedy extensions (the greedy search traps itself: the best first
// texture need not lead to the best pair):
//  - beam = k: the k best first-term candidates (from different starts) are
//    each continued to the end; the branch with the lowest final error (at the
//    final texture size) wins. Branch 1 is the greedy search itself, so the
//    result is never worse than greedy.
//  - backfit_sweeps = s: after term j (j >= 2) is added, every term 1..j is
//    re-searched in turn (cyclically, s sweeps) with the other projections
//    held, from its current rotation (plus backfit_restarts random starts);
//    the objective is the error of the whole fit schedule (thesis 3.2.2) with
//    that one projection changed, so each accepted move lowers the search
//    objective.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "factor/homomorphic_fit.h"
#include "search/powell.h"

namespace bf {

// Bounds that keep memory and time finite for any options (docs/robustness.md).
inline constexpr int kMaxSearchTerms = 64;
inline constexpr int kMaxRestarts = 100000;
inline constexpr uint64_t kMaxTotalTexels = uint64_t(1) << 26;  // terms x texture_size^2
// SearchOptions::search_samples: the default, and the smallest subsample allowed.
inline constexpr size_t kDefaultSearchSamples = 100000;
inline constexpr size_t kMinSearchSamples = 1000;
// The structured search's default polish and beam (SearchOptions::polish_sweeps,
// beam_width): a search of up to this many terms is polished and keeps the wide
// beam. The planted two-plane search (2 terms) needs the beam of 8 (with 4 it
// ends at 3.4x the floor); on 5-term searches the polish and the wider beam
// cost about a third of the time for answers within 1.6% on the paints and
// 2.4% on W1 (Cook-Torrance's 5-term mean over seeds 1-3 rose 23%, still
// 0.17x greedy's; docs/search.md "Search size").
inline constexpr int kSmallSearchTerms = 4;
// Those defaults: for searches of up to kSmallSearchTerms terms, and above.
inline constexpr int kSmallSearchPolishSweeps = 2;
inline constexpr int kLargeSearchPolishSweeps = 0;
inline constexpr int kSmallSearchBeamWidth = 8;
inline constexpr int kLargeSearchBeamWidth = 4;
// "8 for searches of up to 4 terms, 4 above" (help texts of such defaults).
std::string by_search_size(int small, int large);

struct SearchOptions {
  // "structured" (structured_search.h: seeds read off the data's Hessians,
  // screened starts, pair moves, joint polish, per-term parameterization),
  // "greedy" (Cole's search of this file, the thesis's; reproduces the numbers
  // of earlier versions) or "best" (both, keeping the one whose final
  // factorization has the lower rel_mse; with stop_after_term, greedy alone).
  // beam, backfitting and the nlopt optimizers are options of the greedy
  // strategy only.
  std::string strategy = "structured";
  int terms = 2;                        // textures to build, >= 1
  // The parameterization of every term (greedy; structured with term_param = "fixed").
  Parameterization param = Parameterization::WiWo;
  // Structured only: "either" = each term reads the wiwo or the halfdiff point,
  // chosen by the search; "fixed" = every term reads `param`.
  std::string term_param = "either";
  int keep = 3;                         // structured: Powell runs per term (best screened starts), >= 1
  // Structured: the final polish's sweeps (>= 0) and the beam's width (>= 1).
  // The defaults (-1 and 0) depend on the search's size: searches of up to
  // kSmallSearchTerms terms polish with 2 sweeps and keep a beam of 8, longer
  // ones do not polish and keep a beam of 4 (effective_polish_sweeps,
  // effective_beam_width; docs/search.md "Config default").
  int polish_sweeps = -1;
  int beam_width = 0;
  bool final_joint = true;              // structured: the final refit solves all terms jointly
  // Structured, with final_joint: searches of up to this many terms also
  // polish under the joint objective (larger ones polish the schedule's), >= 0.
  int joint_polish_terms = 3;
  // Structured, terms 2..4, term_param "either", final_joint: re-read the terms
  // under the joint objective after the polish (structured_search.h,
  // "re-seeding", with pair restarts from 3 terms; at 2 terms the one-term
  // moves and random restarts of both terms at once); finds planes that do
  // not share a parameterization, at up to about 3.5x the fits (planted
  // 3-term members: 10,000-15,000 -> 19,000-25,000; planted 2-term pairs
  // 2-3x, W1 at 2 terms 4,797 -> 19,278).
  bool reseed = true;
  int texture_size = 16;                // final texture resolution
  int search_texture_size = 0;          // resolution during the search; 0 = texture_size
  int restarts = 6;                     // seeded random starts per term, >= 0
  std::vector<std::string> guesses;     // extra starts: "wi", "wo", "wi+wo"
  bool reciprocity = false;             // every term read through its conjugate too
  // Structured, without `reciprocity`: every k-term answer is also refit with
  // each of its terms read through its conjugate too (the same planes, the
  // terms made reciprocal, solved as the answer was), and that refit replaces
  // the answer when its rel_mse on the fit data is lower. For the samples of a
  // reciprocal BRDF, closed under the swap, it cannot be higher up to the
  // smoothing (the swap-average of the answer is such a fit); on W1's 5-term
  // search it lowers the 2- to 5-term answers 1-20% for one fit per answer
  // (docs/search.md, step 8). Callers turn it on for data that declare
  // reciprocity (config "auto").
  bool final_reciprocity = false;
  FitOptions fit;                       // inner loop (solve_last = n, smoothing, eps)
  uint64_t seed = 1;
  // "powell" (Cole) or an nlopt algorithm: "praxis", "bobyqa", "neldermead",
  // "sbplx", "direct" (global, DIRECT-L), "crs" (global, CRS2 with local mutation).
  std::string optimizer = "powell";
  PowellOptions powell;                 // also: ftol and max_evaluations for nlopt
  int threads = 0;                      // restarts in parallel; 0 = hardware threads
  int beam = 1;                         // first-term candidates continued; 1 = greedy
  int backfit_sweeps = 0;               // cyclic re-search sweeps after each added term
  int backfit_restarts = 0;             // random starts per re-search besides the current rotation
  // Optional stopping rule (a tolerance), greedy search (beam = 1) only: after
  // each added term (and its backfitting), the projections found so far are
  // refit at texture_size and passed here; true ends the search with those
  // terms, so later terms are never searched. Empty: all `terms` are built.
  std::function<bool(const HomomorphicFactorization&)> stop_after_term;
  // Above this many samples the search evaluates its candidates on a
  // stratified subsample of this many (search/subsample.h, seeded by `seed`);
  // the final fit at texture_size and the errors use every sample. 0 = off
  // (every sample). Otherwise >= kMinSearchSamples.
  size_t search_samples = kDefaultSearchSamples;
  void validate() const;                // throws naming the field, value and rule
};

// The polish sweeps and the beam width a structured search runs with: the
// option when set, else the default for the search's size (kSmallSearchTerms).
int effective_polish_sweeps(const SearchOptions& opt);
int effective_beam_width(const SearchOptions& opt);

struct TermRecord {
  std::array<double, 8> rotation;  // quaternion pair [S; T], each [w, x, y, z]
  double search_rel_mse = 0;       // objective at the search resolution
  int evaluations = 0;             // inner-loop fits for this term (all starts)
  double seconds = 0;
  int best_start = 0;              // index of the winning start (restarts first, then guesses)
  int backfit_evaluations = 0;     // fits spent re-searching terms 1..j after this term was added
  int backfit_moves = 0;           // re-searches that lowered the objective
};

struct SearchResult {
  std::shared_ptr<HomomorphicFactorization> factorization;  // at texture_size
  std::vector<TermRecord> terms;
  // At texture_size, fit data: element k-1 is the error of the k-term answer.
  // Greedy: the k-term prefix of `factorization` (the schedule's step k).
  // Structured: answers[k-1], which need not be a prefix of `factorization`.
  std::vector<double> rel_mse_after_term;
  // Structured only: the k-term answer for every k = 1..terms (answers.back()
  // is `factorization`): the better of the final configuration's k-term prefix
  // and the best configuration the beam held after term k, refit jointly at
  // texture_size. Empty for the greedy search (its k-term answer is the prefix).
  std::vector<std::shared_ptr<HomomorphicFactorization>> answers;
  std::string strategy;                    // the strategy that made it ("best": the winner's)
  // With final_reciprocity (structured): element k-1 is true when the k-term
  // answer is the refit with reciprocal terms (it was lower). Else empty.
  std::vector<bool> reciprocal_answers;
  double search_rel_mse = 0;               // final objective at the search resolution
  std::vector<double> beam_rel_mse;        // final error (texture_size) of each beam branch
  int best_branch = 0;                     // the winning branch (0 = the greedy one)
  int evaluations = 0;                     // all inner-loop fits (all branches, backfitting)
  double seconds = 0;
  // The samples the search evaluated its candidates on: search_samples of
  // `data_samples` (equal when every sample was used), drawn with
  // subsample_seed (0 when not subsampled) from subsample_strata strata.
  // `terms[].search_rel_mse`, `search_rel_mse` and `beam_rel_mse` are errors
  // on those samples; `rel_mse_after_term`, `answers` and `factorization` are
  // fitted on every sample.
  size_t search_samples = 0;
  size_t data_samples = 0;
  uint64_t subsample_seed = 0;
  size_t subsample_strata = 0;
};

SearchResult search_factorization(const FitData& data, const SearchOptions& opt);

// Refits r's answers (or, greedy, its factorization) on `data` at
// texture_size as the search refits them (greedy: the schedule; structured:
// all terms solved jointly with final_joint), replacing factorization, answers
// and rel_mse_after_term; each refit adds one to r.evaluations. What
// search_factorization does after a search on a subsample; on the samples the
// search ran on it reproduces r.
void refit_search_result(const FitData& data, const SearchOptions& opt, SearchResult& r);

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
  std::shared_ptr<const JointPrefix> prefix_;  // the held joint terms' part of every solve
};

// The objective of backfitting: the search-objective error of the whole fit
// schedule (terms 1..J = specs, last n joint, thesis 3.2.2) when term `which`
// is read through a candidate rotation and the others are held. Steps that do
// not depend on term `which` are solved once, in the constructor.
class ScheduleObjective {
 public:
  ScheduleObjective(const FitData& data, std::vector<TermSpec> specs, size_t which,
                    const SearchOptions& opt, int res);
  double operator()(const Rotation4& r) const;

 private:
  const FitData& data_;
  std::vector<TermSpec> specs_;
  size_t which_, first_step_;
  std::vector<FactorTerm> prefix_;                  // terms fixed before first_step_
  std::array<std::vector<double>, 3> prefix_values_;
  const SearchOptions& opt_;
  int res_;
};

// The first term solved jointly when term `step` (0-based) is added under a
// schedule that solves the last `solve_last` terms jointly (FitOptions::solve_last).
inline size_t first_joint(size_t step, int solve_last) {
  return step + 1 > static_cast<size_t>(solve_last) ? step + 1 - solve_last : 0;
}

}  // namespace bf
