// The homomorphic kinds' shared keys, refinement stage, columns and export (see homomorphic.h).
#include "experiments/methods/homomorphic.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "experiments/common/cli_util.h"
#include "factor/export.h"
#include "factor/refine.h"
#include "factor/size_select.h"

namespace bf {

using nlohmann::json;

std::vector<KeySpec> fit_keys(const KeySpec& texture_size) {
  return {texture_size,
          num_key("smoothing", 0.0, FitOptions::kMaxWeight, false, "1e-3",
                  "Laplacian weight relative to the mean sample weight per texel; `\"cv\"` (raw samples): chosen "
                  "by held-out error from 1e-4, 1e-3, 1e-2, 0.1, 1 (the search: its projections, found once at "
                  "1e-3, refit per candidate; docs/design.md §4.1 \"cv\")"),
          num_key("eps", 0.0, 1.0, true, "1e-5", "log-transform eps of the fit (docs/design.md §2)"),
          num_key("extrapolation_prior", 0.0, FitOptions::kMaxWeight, false, "0",
                  "weight (in mean sample weights) pulling the fit toward the data's mean log value where no "
                  "sample lies (docs/design.md §3.2); 0 = off (pure Laplacian extrapolation)"),
          bool_key("clamp_log_range", "true",
                   "clamp the summed log value to the training targets' log range before exp (docs/design.md "
                   "§3.2): bounded extrapolation, never a worse training error; false = unclamped"),
          bool_key("subtract_eps", "true",
                   "reconstruct A·exp(s) − eps·A (clamped at 0) instead of A·exp(s); run.json says which"),
          int_key("solve_last", 1, 64, "2", "n: the last n terms are solved jointly (thesis 3.2.2)"),
          choice_key("solver", {"auto", "dense", "sparse", "qr"}, "auto",
                     "linear solver of the fit; qr is the slow reference path")};
}

KeySpec homomorphic_texture_key() {
  return other_key("texture_size", "integer 2..1024, `\"auto\"` or `\"cv\"`", "16",
                   "textures are texture_size² texels; `\"auto\"`: chosen by the tolerance from `texture_ladder`; "
                   "`\"cv\"` (raw samples): chosen by held-out error from 8, 12, 16, 24, 32 (docs/design.md §4.1 "
                   "\"cv\")");
}

std::vector<KeySpec> refine_keys() {
  return {num_key("refine_blend", 0.0, RefineOptions::kMaxWeight, false, "0.03",
                  "`blend` only: weight of the linear-space residuals against the log-space ones (0 = rel_mse alone)"),
          int_key("refine_iterations", 1, 100000, "50", "Levenberg–Marquardt iterations at most"),
          num_key("refine_smoothing", 0.0, RefineOptions::kMaxWeight, false, "the method's `smoothing`",
                  "Laplacian weight of the refinement, in the fit's units")};
}

namespace {

FitOptions::Solver parse_solver(const std::string& s) {
  if (s == "dense") return FitOptions::Solver::Dense;
  if (s == "sparse") return FitOptions::Solver::Sparse;
  if (s == "qr") return FitOptions::Solver::ReferenceQR;
  return FitOptions::Solver::Auto;
}

const KeySpec& fit_key(const std::string& name) {
  static const std::vector<KeySpec> keys = fit_keys(homomorphic_texture_key());
  return find_key(keys, name);
}

const KeySpec& refine_key(const std::string& name) {
  static const std::vector<KeySpec> keys = refine_keys();
  return find_key(keys, name);
}

}  // namespace

bool take_texture_cv(Reader& r, json& o, bool auto_ok) {
  const auto it = r.combo().find("texture_size");
  if (it == r.combo().end() || it->second->is_integer()) return false;
  const std::optional<std::string> s = it->second->value<std::string>();
  if (auto_ok && s == std::optional<std::string>("auto")) return false;
  r.take("texture_size");
  if (s != std::optional<std::string>("cv")) {
    r.fail("texture_size", "expected an integer in " + std::to_string(kFitTextureMin) + ".." +
                               std::to_string(kFitTextureMax) + (auto_ok ? ", \"auto\" or" : " or") + " \"cv\", " +
                               found(*it->second));
    return true;
  }
  o["texture_size"] = "cv";
  if (r.take("texture_ladder"))
    r.fail("texture_ladder", "texture_ladder applies only with texture_size = \"auto\"; texture_size = \"cv\" "
                             "tries 8, 12, 16, 24, 32");
  return true;
}

void read_fit_options(Reader& r, FitOptions& f, json& o) {
  f.eps = r.number(fit_key("eps"), f.eps);
  // smoothing: a number, or "cv" (chosen per run by finish_refine_options).
  bool cv = false;
  const toml::node* sm = r.has("smoothing") ? r.combo().at("smoothing") : nullptr;
  if (sm && !sm->is_number()) {
    r.take("smoothing");
    cv = sm->value<std::string>() == std::optional<std::string>("cv");
    const KeySpec& k = fit_key("smoothing");
    if (!cv) r.fail("smoothing", "expected a number in [" + fmt_num(k.lo) + ", " + fmt_num(k.hi) + "] or \"cv\", " + found(*sm));
  } else {
    f.smoothing = r.number(fit_key("smoothing"), f.smoothing);
  }
  f.extrapolation_prior = r.number(fit_key("extrapolation_prior"), f.extrapolation_prior);
  f.subtract_eps = r.boolean(fit_key("subtract_eps"), f.subtract_eps);
  f.clamp_log_range = r.boolean(fit_key("clamp_log_range"), f.clamp_log_range);
  f.solve_last = static_cast<int>(r.integer(fit_key("solve_last"), f.solve_last));
  const std::string solver = r.choice(fit_key("solver"), "auto");
  f.solver = parse_solver(solver);
  o["eps"] = f.eps;
  o["smoothing"] = cv ? json("cv") : json(f.smoothing);  // "cv": chosen per run (finish_refine_options)
  o["extrapolation_prior"] = f.extrapolation_prior;
  o["subtract_eps"] = f.subtract_eps;
  // Only when off: the default keeps the run ids of configs written before the key.
  if (!f.clamp_log_range) o["clamp_log_range"] = false;
  o["solve_last"] = f.solve_last;
  o["solver"] = solver;
}

void read_refine_options(Reader& r, MethodVariant& m, json& o) {
  RefineOptions& ro = homomorphic_options(m).refine;
  ro.objective = m.refine == "none" ? ro.objective : m.refine;
  ro.blend_weight = r.number(refine_key("refine_blend"), ro.blend_weight);
  ro.max_iterations = static_cast<int>(r.integer(refine_key("refine_iterations"), ro.max_iterations));
  const bool own_smoothing = r.has("refine_smoothing");
  ro.smoothing = r.number(refine_key("refine_smoothing"), ro.smoothing);
  if (m.refine != "none") {
    if (m.refine == "blend") o["refine_blend"] = ro.blend_weight;
    o["refine_iterations"] = ro.max_iterations;
    // Default: the fit's own smoothing (filled in by finish_refine_options).
    o["refine_smoothing"] = own_smoothing ? json(ro.smoothing) : json();
  }
  if (!own_smoothing) ro.smoothing = -1;  // = the fit's smoothing
}

void validate_fit_options(Reader& r, const MethodVariant& m) {
  if (r.failed()) return;
  try {
    homomorphic_options(m).fit.validate();
  } catch (const std::exception& e) {
    report_invalid(r, e, method_keys(*m.impl));
  }
}

void finish_refine_options(Reader& r, MethodVariant& m, json& o) {
  HomomorphicOptions& ho = homomorphic_options(m);
  RefineOptions& ro = ho.refine;
  const bool refine_follows = ro.smoothing < 0;  // the refinement uses the fit's smoothing
  // Keys chosen by held-out error (docs/design.md §4.1 "cv"): the smoothing,
  // the texture size, or both (their grid, size-major).
  const bool cv_smoothing = o.value("smoothing", json()) == json("cv");
  const bool cv_size = o.value("texture_size", json()) == json("cv");
  const auto set_smoothing = [refine_follows](MethodVariant& mv, double v) {
    HomomorphicOptions& h = homomorphic_options(mv);
    h.fit.smoothing = v;
    h.search.fit.smoothing = v;
    if (refine_follows) h.refine.smoothing = v;
    mv.options["smoothing"] = v;
  };
  const auto set_size = [](MethodVariant& mv, int n) {
    HomomorphicOptions& h = homomorphic_options(mv);
    mv.texture_size = n;
    h.projections = terms_at_resolution(h.projections, n);
    h.search.texture_size = n;
    mv.options["texture_size"] = n;
  };
  if (cv_smoothing && cv_size) {
    std::vector<double> grid;
    for (size_t i = 0; i < kCvTextureLadder.size() * kCvSmoothingLadder.size(); ++i) grid.push_back(double(i));
    m.cv = MethodVariant::HeldOutChoice{kCvGridKey, grid, [set_smoothing, set_size](MethodVariant& mv, double v) {
                                          const size_t i = static_cast<size_t>(v), n = kCvSmoothingLadder.size();
                                          set_size(mv, kCvTextureLadder[i / n]);
                                          set_smoothing(mv, kCvSmoothingLadder[i % n]);
                                        }};
  } else if (cv_smoothing) {
    m.cv = MethodVariant::HeldOutChoice{"smoothing", kCvSmoothingLadder, set_smoothing};
  } else if (cv_size) {
    m.cv = MethodVariant::HeldOutChoice{"texture_size",
                                        std::vector<double>(kCvTextureLadder.begin(), kCvTextureLadder.end()),
                                        [set_size](MethodVariant& mv, double v) { set_size(mv, int(v)); }};
  }
  if (m.cv && m.kind == "search" && m.tolerance)
    r.fail(cv_smoothing ? "smoothing" : "texture_size",
           "\"cv\" refits the search's projections per candidate, but a tolerance stops the search at a term "
           "count; give a number, or remove the tolerance");
  if (ro.smoothing < 0) ro.smoothing = ho.fit.smoothing;
  if (m.refine != "none") o["refine_smoothing"] = ro.smoothing;
  ro.threads = 1;
  if (r.failed()) return;
  try {
    ro.validate();
  } catch (const std::exception& e) {
    report_invalid(r, e, method_keys(*m.impl), "refinement: ",
                   {{"blend_weight", "refine_blend"}, {"max_iterations", "refine_iterations"},
                    {"smoothing", "refine_smoothing"}});
  }
}

MethodOutcome finish_homomorphic(const RunContext& c, HomomorphicRun run, std::optional<SizeChoice> choice,
                                 int evaluations) {
  const MethodVariant& m = c.method;
  const RefineOptions& ro = homomorphic_options(m).refine;
  MethodOutcome out;
  out.choice = std::move(choice);
  out.evaluations = evaluations;
  // Refinement (factor/refine.h): the row reports the refined factorization,
  // the *_before columns the fit it started from.
  if (m.refine != "none") {
    run.before = evaluate_metrics(*run.h, c.samples, c.lt);
    const auto t0 = std::chrono::steady_clock::now();
    RefineReport rep;
    try {
      run.h = refine(*run.h, c.samples, ro, &rep);
      out.record["refinement"] = {{"objective", rep.objective},        {"linear_solver", rep.linear_solver},
                                  {"iterations", rep.iterations},      {"seconds", rep.seconds},
                                  {"initial_cost", rep.initial_cost},  {"final_cost", rep.final_cost},
                                  {"termination", rep.termination},    {"parameters", rep.parameters},
                                  {"residuals", rep.residuals},        {"texels_added", rep.texels_added},
                                  {"blend_weight", ro.blend_weight},
                                  {"smoothing", ro.smoothing}};
    } catch (const std::runtime_error& ex) {
      // Ceres found no finite solution: the start is the best answer.
      out.notes.push_back(std::string("refinement failed, unrefined fit kept: ") + ex.what());
      out.record["refinement"] = {{"failed", ex.what()}};
    }
    run.refine_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  out.result = run.h;
  out.state = std::move(run);
  return out;
}

std::vector<std::string> homomorphic_columns() {
  return {"parameterization", "reciprocity", "terms", "texture_size", "errors_after_term", "term_parameterizations"};
}

// Also term_parameterizations: each term's parameterization, in order. The
// parameterization column is the terms' distinct ones; the search kind puts
// what its options ask there instead.
void fill_homomorphic_row(const RunContext& c, MethodOutcome& out, Row& row) {
  const auto& run = std::any_cast<const HomomorphicRun&>(out.state);
  const HomomorphicFactorization& h = *run.h;
  std::vector<std::string> params, per_term;
  size_t recip = 0, symmetric = 0;
  for (const auto& t : h.terms()) {
    per_term.push_back(to_string(t.proj.param));
    if (std::find(params.begin(), params.end(), to_string(t.proj.param)) == params.end())
      params.push_back(to_string(t.proj.param));
    recip += t.reciprocal;
    symmetric += t.reciprocal || t.proj.self_conjugate();
  }
  row["parameterization"] = join(params, "+");
  row["term_parameterizations"] = join(per_term, "+");  // one entry per term, in order
  // true: every term is read through its conjugate or is its own conjugate
  // (McCool's p(h) texture), so the approximation is reciprocal.
  row["reciprocity"] = recip == 0 ? "false" : symmetric == h.terms().size() ? "true" : "mixed";
  row["terms"] = std::to_string(h.terms().size());
  row["texture_size"] = std::to_string(out.choice && out.choice->texture_size ? out.choice->texture_size
                                                                              : c.method.texture_size);
  std::vector<std::string> ec;
  for (double v : run.errors_after_term) ec.push_back(format_number(v));
  row["errors_after_term"] = join(ec, ";");
  out.record["reconstruction"] =
      std::string(h.log_range() ? "A exp(clamp(s, log_range)" : "A exp(s") +
      (h.subtract_eps() ? ") - eps A, clamped at 0" : ")");
  if (c.method.refine == "none") return;
  row["refine"] = c.method.refine;
  row["refine_seconds"] = format_number(std::round(run.refine_seconds * 1000.0) / 1000.0);
  const Metrics& b = run.before;
  const std::pair<const char*, double> cells[] = {
      {"rel_mse_before", b.rel_mse},   {"rel_mae_before", b.rel_mae}, {"rel_max_before", b.rel_max},
      {"lin_rmse_before", b.lin_rmse}, {"lin_mae_before", b.lin_mae}, {"lin_max_before", b.lin_max},
      {"cos_rmse_before", b.cos_rmse}};
  for (const auto& [k, v] : cells) row[k] = format_number(v);
}

void export_homomorphic(const RunContext& c, const MethodOutcome& out) {
  write_export(*out.result, c.run_dir.string(), "factors");  // out.result is the run's (refined) fit
}

}  // namespace bf
