// What the homomorphic kinds (mccool, fit, search) share: the fit keys, the
// refinement stage (refine = "linear" | "cosine" | "blend", factor/refine.h)
// run after their fit, their results columns and their exported factors.
#pragma once

#include <memory>
#include <vector>

#include "experiments/methods/method_kind.h"
#include "factor/homomorphic_fit.h"
#include "factor/refine.h"
#include "search/term_search.h"

namespace bf {

// The search's state under a key chosen by held-out error (search.cpp): the
// search at the base options, once per training set, shared by the variant's
// copies (candidates, folds, the run's own fit).
struct SearchCvCache;

// The typed options of the homomorphic kinds (MethodVariant::typed).
struct HomomorphicOptions {
  Parameterization param = Parameterization::WiWo;
  bool reciprocity = false;
  // search: "auto" (on when the BRDF declares reciprocity and sampling.symmetries
  // does not leave it out), "true" or "false" (SearchOptions::final_reciprocity).
  std::string final_reciprocity = "auto";
  FitOptions fit;                    // mccool, fit, search (search.fit mirrors it)
  std::vector<TermSpec> projections; // fit: all configured projections at texture_size
  SearchOptions search;              // search
  RefineOptions refine;              // the refinement stage (MethodVariant::refine names it)
  std::shared_ptr<SearchCvCache> search_cv;  // search with a "cv" key: set by the search's reader
};
inline HomomorphicOptions& homomorphic_options(MethodVariant& m) { return kind_options<HomomorphicOptions>(m); }
inline const HomomorphicOptions& homomorphic_options(const MethodVariant& m) {
  return kind_options<HomomorphicOptions>(m);
}

// `smoothing = "cv"` (mccool, fit; raw samples): the candidates, tried by
// held-out error (k-fold, or the single held-out fraction), in this order;
// the first of equal errors wins. Decades around the default 1e-3.
inline const std::vector<double> kCvSmoothingLadder = {1e-4, 1e-3, 1e-2, 1e-1, 1.0};
// `texture_size = "cv"` (mccool, fit, search; raw samples): the resolutions
// tried the same way, the default 16 in the middle.
inline const std::vector<int> kCvTextureLadder = {8, 12, 16, 24, 32};

// The key chosen by held-out error when both are "cv": the grid
// kCvTextureLadder x kCvSmoothingLadder, size-major (MethodVariant::cv.key).
inline const char* const kCvGridKey = "texture_size and smoothing";

// texture_size = "cv": takes the key when its value is the string "cv" and
// records o["texture_size"] = "cv" (finish_refine_options then sets
// MethodVariant::cv). Any other value that is not an integer (nor "auto"
// where auto_ok) is reported here, naming every accepted form (an integer
// in 2..1024, "auto" where accepted, "cv"), and taken. False, untouched,
// for an integer, "auto" where accepted, or no key.
bool take_texture_cv(Reader& r, nlohmann::json& o, bool auto_ok);

// The fit keys (texture_size with the given default docs, smoothing, eps,
// subtract_eps, solve_last, solver) and the refinement keys.
std::vector<KeySpec> fit_keys(const KeySpec& texture_size);
std::vector<KeySpec> refine_keys();
// texture_size of mccool and fit: an integer or "auto" (read_texture_size).
KeySpec homomorphic_texture_key();
constexpr int kFitTextureMin = 2, kFitTextureMax = 1024;

// Reads smoothing, extrapolation_prior, eps, subtract_eps, solve_last, solver into f and o.
void read_fit_options(Reader& r, FitOptions& f, nlohmann::json& o);
// The refinement keys, read first (whatever refine is, so a sweep over refine
// can carry them) and hashed only when a refinement runs.
void read_refine_options(Reader& r, MethodVariant& m, nlohmann::json& o);
// After the kind's keys: the refinement's default smoothing (the fit's) and its validation.
void finish_refine_options(Reader& r, MethodVariant& m, nlohmann::json& o);
// FitOptions::validate, reported at the table.
void validate_fit_options(Reader& r, const MethodVariant& m);

// A homomorphic run's state (MethodOutcome::state).
struct HomomorphicRun {
  std::shared_ptr<const HomomorphicFactorization> h;  // after refinement, if any
  std::vector<double> errors_after_term;              // of the fit
  Metrics before;                                     // the fit's metrics when refined
  double refine_seconds = 0;
};

// Runs the refinement stage when m.refine != "none" and builds the outcome
// (result, state, record "refinement", the note of a failed refinement).
MethodOutcome finish_homomorphic(const RunContext& c, HomomorphicRun run, std::optional<SizeChoice> choice,
                                 int evaluations);
// Columns parameterization, reciprocity, terms, texture_size, errors_after_term,
// refine, refine_seconds, *_before; run.json "reconstruction".
void fill_homomorphic_row(const RunContext& c, MethodOutcome& out, Row& row);
std::vector<std::string> homomorphic_columns();
// factors/: textures, sidecar, GLSL.
void export_homomorphic(const RunContext& c, const MethodOutcome& out);

// Base of the homomorphic kinds: refinable, their columns, row and export.
class HomomorphicKind : public MethodKind {
 public:
  bool refinable() const override { return true; }
  std::vector<std::string> columns() const override { return homomorphic_columns(); }
  void fill_row(const RunContext& c, MethodOutcome& out, Row& row) const override {
    fill_homomorphic_row(c, out, row);
  }
  void export_files(const RunContext& c, const MethodOutcome& out) const override { export_homomorphic(c, out); }
  // The fit's errors after each term, and its metrics before a refinement.
  void report_call(const RunContext& c, const MethodOutcome& out, bool samples_given,
                   std::vector<double>& errors_after_term, nlohmann::json& info) const override {
    (void)samples_given;
    const auto* h = std::any_cast<HomomorphicRun>(&out.state);
    if (!h) return;
    errors_after_term = h->errors_after_term;
    if (c.method.refine != "none")
      info["metrics_before_refine"] = {
          {"rel_mse", h->before.rel_mse}, {"lin_rmse", h->before.lin_rmse}, {"cos_rmse", h->before.cos_rmse}};
  }
};

}  // namespace bf
