// Experiment runner (see runner.h).
#include "experiments/run/runner.h"

#include "experiments/config/config.h"

#include "brdfs/safe_path.h"
#include "experiments/run/interrupt.h"
#include "experiments/run/outdir_lock.h"
#include "experiments/report/plot_step.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <unistd.h>

#include "brdfs/sampleset.h"
#include "experiments/common/cli_util.h"
#include "experiments/report/render.h"
#include "experiments/report/scene_weights.h"
#include "experiments/run/sample_cache.h"
#include "experiments/run/sampling_run.h"
#include "experiments/run/preflight.h"
#include "experiments/run/run_folder.h"
#include "experiments/methods/method_kind.h"
#include "experiments/report/validation.h"
#include "experiments/run/symmetry_prep.h"
#include "experiments/run/folds.h"
#if __has_include("brdfs/measured.h")
#include "brdfs/measured.h"
#define BF_RUNNER_HAVE_MEASURED 1
#endif
#include "experiments/report/viewer.h"
#include "solvers/cancel.h"
#include "factor/isotropy.h"
#include "factor/metrics.h"
#include "solvers/parallel.h"

namespace bf {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string hms(double s) {
  if (!(s >= 0) || !std::isfinite(s)) return "?";
  const long t = std::lround(s);
  char buf[32];
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else std::snprintf(buf, sizeof buf, "%ld:%02ld", t / 60, t % 60);
  return buf;
}

// ------------------------------------------------------------------ one run


std::string describe_method(const MethodVariant& m) {
  std::string s = m.label;
  if (m.label != m.kind) s += " (" + m.kind + ")";
  for (const auto& k : m.impl->described())
    if (m.options.contains(k)) {
      const json v = m.impl->described_value(m, k);
      if (v.is_number_integer() && v.get<int64_t>() < 0) continue;  // -1: chosen at run time (sh-r orders)
      s += " " + k + "=" + (v.is_string() ? v.get<std::string>() : v.dump());
    }
  if (m.tolerance) s += " tolerance=" + m.tolerance->metric + "<=" + format_number(m.tolerance->value);
  if (m.refine != "none") s += " refine=" + m.refine;
  if (const auto wf = m.options.find("weight_fit"); wf != m.options.end())
    s += " weight_fit=" + wf->at("rule").get<std::string>() + " weight_floor=" + format_number(wf->at("floor").get<double>());
  return s;
}

std::string describe_run(const Plan& plan, const PlannedRun& r) {
  return plan.brdfs[r.brdf].label + " | " + plan.samplings[r.sampling].label + " | " +
         describe_method(plan.methods[r.method]);
}

// Original-BRDF renders and whole-domain validation sets are shared by every
// run of a BRDF.
class RenderCache {
 public:
  std::shared_ptr<const SphereRender> get(const Plan& plan, size_t brdf) {
    std::unique_lock<std::mutex> lk(mu_);
    auto& slot = map_[brdf];
    if (!slot) slot = std::make_shared<SphereRender>(render_sphere(*plan.brdfs[brdf].brdf, plan.scene));
    return slot;
  }
  // nullptr when experiment.validation_pairs = 0.
  std::shared_ptr<const DomainSet> validation(const Plan& plan, size_t brdf) {
    if (plan.experiment.validation_pairs == 0) return nullptr;
    std::unique_lock<std::mutex> lk(mu_);
    auto& slot = sets_[brdf];
    if (!slot)
      slot = std::make_shared<DomainSet>(domain_set(*plan.brdfs[brdf].brdf, plan.experiment.validation_pairs,
                                                    validation_seed(plan.experiment.seed)));
    return slot;
  }

 private:
  std::mutex mu_;
  std::map<size_t, std::shared_ptr<const SphereRender>> map_;
  std::map<size_t, std::shared_ptr<const DomainSet>> sets_;
};

// The validation scheme of a run, in words (the `validation` column).
std::string validation_scheme(const Plan& plan, const BrdfVariant& b, const DomainSet* domain,
                              const ValidationScores& vs, const HoldoutSplit* split, const FoldSummary* folds,
                              size_t all_valid) {
  std::vector<std::string> parts;
  if (domain && !vs.domain) {
    parts.push_back("domain: no pair of the set where the " + std::string(b.measured ? "interpolant" : "BRDF") +
                    " has data");
  } else if (domain) {
    const size_t no_data = vs.pairs - vs.val.samples;  // masked pairs of the prefix scored
    const std::string seed = "seed " + std::to_string(validation_seed(plan.experiment.seed));
    std::string how = std::to_string(vs.pairs) + " stratified pairs (" + seed + ")";
    if (domain->block_pairs > 0)
      how = std::to_string(vs.pairs) + " stratified pairs in " + std::to_string(vs.blocks) + " blocks of " +
            std::to_string(domain->block_pairs) + " (validation_pairs = \"auto\": standard error of val_rel_mse " +
            format_short(format_number(100.0 * vs.rel_se)) + "%, target " +
            format_number(100.0 * ExperimentSettings::kValidationTargetSe) + "% or " +
            std::to_string(domain->blocks * domain->block_pairs) + " pairs; " + seed + ")";
    parts.push_back("domain: " + how + " vs the " + (b.measured ? "interpolant" : "BRDF") +
                    (no_data > 0 ? " (" + std::to_string(no_data) + " where it has no data skipped)"
                         : std::string()));
  }
  if (split)
    parts.push_back("held out: " + std::to_string(split->held.valid_count()) + " of " + std::to_string(all_valid) +
                    " samples (" + format_number(plan.experiment.holdout * 100.0) + "%" +
                    (plan.experiment.folds == ExperimentSettings::kFoldsAuto
                         ? "; folds = \"auto\": more than " +
                               std::to_string(ExperimentSettings::kAutoFoldsMaxSamples) + " valid samples"
                         : std::string()) +
                    "), not fitted");
  if (folds)
    parts.push_back("held out: " + std::to_string(folds->folds) + "-fold (" +
                    (plan.experiment.folds == ExperimentSettings::kFoldsAuto
                         ? "folds = \"auto\": at most " + std::to_string(ExperimentSettings::kAutoFoldsMaxSamples) +
                               " valid samples; "
                         : std::string()) +
                    "seed " +
                    std::to_string(validation_seed(plan.experiment.seed)) + "), each of " +
                    std::to_string(all_valid) + " samples held out once; holdout_* are the mean over the folds (" +
                    folds->spread() + "); the scored fit uses every sample");
  return join(parts, "; ");
}

// With a tolerance on a metric not scored on the fit's samples (shade_rmse,
// val_*: factor/size_choice.h), the method's copy with the scorer set: every
// kind's selection then judges candidates by the scene or the validation set.
MethodVariant with_tolerance_scorer(const MethodVariant& m, const Plan& plan, const PlannedRun& pr,
                                    RenderCache& renders, std::shared_ptr<const DomainSet> domain,
                                    const LogTransform& lt) {
  MethodVariant mv = m;
  if (!mv.tolerance || !is_external_metric(mv.tolerance->metric)) return mv;
  const std::string metric = mv.tolerance->metric;
  if (metric == "shade_rmse") {
    std::shared_ptr<const SphereRender> original = renders.get(plan, pr.brdf);
    const SceneSettings scene = plan.scene;
    mv.tolerance->score = [original, scene](const Brdf& cand) {
      return shade_rmse(*original, render_sphere(cand, scene));
    };
  } else {
    if (!domain)
      throw std::runtime_error("tolerance " + metric +
                               " needs a whole-domain validation set: validation_pairs \"auto\" or > 0 and a BRDF that is a "
                               "truth over the whole domain (an interpolant whose samples declare "
                               "isotropic+reciprocal+bilateral; docs/design.md §4.3)");
    mv.tolerance->score = [domain, lt, metric](const Brdf& cand) {
      const ValidationScores v = score_validation(cand, domain.get(), nullptr, lt);
      return metric == "val_max_ratio" ? v.max_ratio : metric_value(v.val, metric.substr(4));
    };
  }
  return mv;
}

// The options in which a method variant differs from the other variants of
// its [[method]] table (its sweep values), as "key=value ...".
std::string sweep_of(const Plan& plan, size_t method) {
  const MethodVariant& m = plan.methods[method];
  std::vector<std::string> parts;
  for (const auto& [k, v] : m.options.items()) {
    bool varies = false;
    for (const auto& o : plan.methods)
      if (&o != &m && o.where == m.where && (!o.options.contains(k) || o.options[k] != v)) varies = true;
    if (varies) parts.push_back(k + "=" + (v.is_string() ? v.get<std::string>() : v.dump()));
  }
  return join(parts, " ");
}

void set_presentation(Row& row, const Plan& plan, const PlannedRun& r) {
  row["sweep"] = sweep_of(plan, r.method);
  row["run_id"] = r.run_id;
  row["brdf"] = plan.brdfs[r.brdf].label;
  row["method"] = plan.methods[r.method].kind;
  row["label"] = plan.methods[r.method].label;
  row["sampling"] = plan.samplings[r.sampling].label;
}

// The results column and run.json entry `symmetries`: the key, what the samples
// declare, what the fit used, its orbit, and whether metrics score the orbit.
void record_symmetries(const SymmetryChoice& sym, const OrbitInfo& orbit, Row& row, json& rec) {
  row["symmetries"] = sym.used.to_string();
  rec["symmetries"] = {{"key", sym.key}, {"declared", sym.declared.to_string()}, {"used", sym.used.to_string()}};
  if (sym.used.any()) rec["symmetries"]["orbit"] = orbit.describe();
  if (sym.score_orbit) rec["symmetries"]["metrics"] = scored_over_orbit_note(sym);
}

// Training or held-out metrics of f on s, scored where scored_set says.
Metrics scored_metrics(const Brdf& f, const SampleSet& s, const SymmetryChoice& sym, const LogTransform& lt) {
  std::optional<SampleSet> orbit;
  return evaluate_metrics(f, scored_set(s, sym, orbit), lt);
}

// What the held-out fits of a run found (held_out_stage).
struct HeldOutStage {
  std::optional<FoldSummary> folds;  // with experiment.folds: the folds' scores
  json folds_record;                 // each fold's sizes and scores (run.json validation.folds)
  double folds_seconds = 0;
  std::string cv_note;               // with a key chosen by held-out error: the choice in words
};

// What every fit of a run is given (the run's own fit and each held-out
// fit): the BRDF, for a measured one fitted without held-out samples the BRDF
// made of its training samples only (the tabulating kinds read it, the fill
// samples it, so no held-out sample reaches a fit), the whole-domain fill, and
// the fit set (the training samples' orbit plus the fill).
struct FitPrep {
  BrdfVariant brdf;
  BrdfPtr training;  // measured: the BRDF made of `train` (the fill's truth), else null
  FillChoice fill;   // fill.truth points into `training` or brdf's shared BRDF
  SampleSet view;
};
FitPrep prepare_fit(const Plan& plan, const PlannedRun& pr, const SampleSet& train, bool held_out,
                    const SymmetryChoice& sym, OrbitInfo* orbit) {
  FitPrep p{plan.brdfs[pr.brdf], nullptr, {}, {}};
#ifdef BF_RUNNER_HAVE_MEASURED
  // The fill reads the training BRDF whether or not samples were held out (a
  // MERL table's is read trilinearly; with the table's own nearest lookup a fit
  // without held-out cells was 5x worse than one with them); the tabulating
  // kinds see it only when samples were held out.
  if (p.brdf.measured) p.training = measured_from_training(*p.brdf.brdf, train);
  if (held_out && p.training) p.brdf.brdf = p.training;
#endif
  const Brdf* truth = p.training ? p.training.get() : p.brdf.measured ? p.brdf.brdf.get() : nullptr;
  p.fill = choose_fill(plan.samplings[pr.sampling], truth, sym, fill_seed(plan.experiment.seed));
  p.view = with_fill(fit_set(train, sym, orbit), p.fill);
  return p;
}

// The held-out data of a run on raw samples (experiments/report/validation.h,
// experiments/run/folds.h): a fraction held out of the fit, or with
// experiment.folds the k folds, fitted separately (nothing is held out of the
// run's own fit then). Neither for grid and stratified samplings.
struct HeldOutData {
  std::vector<HoldoutSplit> folds;
  std::optional<HoldoutSplit> split;
};
HeldOutData held_out_data(const Plan& plan, const PlannedRun& pr, const SampleSet& samples) {
  HeldOutData d;
  const SamplingVariant& s = plan.samplings[pr.sampling];
  const uint64_t seed = validation_seed(plan.experiment.seed);
  const int k = folds_for(s, plan.experiment, samples.valid_count());
  if (k >= 2)
    d.folds = split_folds(samples, k, seed);
  else if (holds_out(s, plan.experiment))
    d.split = split_holdout(samples, plan.experiment.holdout, seed);
  return d;
}

// run.json validation entries beyond the scheme: the pairs scored (with
// "auto" also the blocks and the relative standard error of val_rel_mse),
// the per-channel rel_mse (R, G, B) of the run's fit on the whole-domain set
// and the held-out samples, and each fold's scores.
void record_held_out(json& v, const ValidationScores& vs, const DomainSet* domain, const HoldoutSplit* split,
                     const HeldOutStage& held) {
  json per_channel = json::object();
  if (vs.domain && domain) {
    v["pairs"] = vs.pairs;
    if (domain->block_pairs > 0) v["blocks"] = vs.blocks, v["val_rel_mse_standard_error"] = vs.rel_se;
    per_channel["val"] = vs.val.rel_mse_channel;
  }
  if (split && vs.holdout) per_channel["holdout"] = vs.held.rel_mse_channel;
  if (!per_channel.empty()) v["channel_rel_mse"] = per_channel;
  if (held.folds) {
    v["folds"] = held.folds_record;
    v["folds_seconds"] = held.folds_seconds;
  }
}

// The held-out fits of a run on raw samples (docs/design.md §4.1): for a key
// chosen by held-out error (MethodVariant::cv), every candidate fitted without
// the held-out samples (each fold, or the single fraction) and the choice set
// on m; with folds, the method fitted without each fold. Entries go to rec.
HeldOutStage held_out_stage(const Plan& plan, const PlannedRun& pr, const MethodKind& kind, MethodVariant& m,
                            const SymmetryChoice& sym, const IsotropyResult& isotropy, const fs::path& run_dir,
                            RenderCache& renders, const std::vector<HoldoutSplit>* folds,
                            const HoldoutSplit* split, json& rec) {
  const BrdfVariant& b = plan.brdfs[pr.brdf];
  // One fit of the method without the held-out samples h.held (the same
  // preparation as the run's own fit: symmetries, the training-only BRDF of
  // the tabulating kinds, scene weights), scored on them.
  auto held_out_score = [&](const HoldoutSplit& h, const MethodVariant& mv) {
    const LogTransform flt = LogTransform::of(h.train, plan.experiment.metric_eps);
    const FitPrep prep = prepare_fit(plan, pr, h.train, true, sym, nullptr);
    const BrdfVariant& fb = prep.brdf;
    const SampleSet& view = prep.view;
    std::optional<SampleSet> wv;
    if (const auto wf = mv.options.find("weight_fit"); wf != mv.options.end())
      wv = scene_weighted(view, scene_pairs(*b.brdf, plan.scene), wf->at("floor").get<double>());
    const RunContext fc{plan, pr, fb, mv, wv ? *wv : view, flt, isotropy, run_dir,
                        [&] { return renders.get(plan, pr.brdf); }};
    const MethodOutcome fo = kind.run(fc);
    if (!fo.result) throw std::runtime_error("method " + mv.kind + " returned no factorization");
    return scored_metrics(*fo.result, h.held, sym, flt);
  };
  // A key chosen by held-out error (MethodVariant::cv): each candidate fitted
  // without the held-out samples (every fold, or the single fraction), the
  // lowest mean held-out rel_mse chosen; the run's fit then uses the choice.
  std::vector<Metrics> chosen_folds;
  HeldOutStage st;
  std::string& cv_note = st.cv_note;
  const bool use_folds = folds != nullptr;
  if (m.cv) {
    if (!use_folds && !split)
      throw std::invalid_argument(m.cv->key + " = \"cv\" needs held-out samples (raw samples with holdout or folds)");
    const auto tc = Clock::now();
    json cands = json::array();
    std::vector<std::string> words;
    size_t best = 0;
    double best_err = std::numeric_limits<double>::infinity();
    std::vector<std::vector<Metrics>> per_candidate;
    // Several keys chosen together ("texture_size and smoothing"): the ladder
    // numbers the grid; each candidate's values are read from the options
    // its apply set.
    std::vector<std::string> parts;
    for (size_t at = 0, and_at; at <= m.cv->key.size(); at = and_at + 5) {
      and_at = m.cv->key.find(" and ", at);
      if (and_at == std::string::npos) and_at = m.cv->key.size();
      parts.push_back(m.cv->key.substr(at, and_at - at));
    }
    const auto values_of = [&](const MethodVariant& mv, std::string* label) {
      json v = json::object();
      std::vector<std::string> shown;
      for (const std::string& p : parts) {
        v[p] = mv.options.value(p, json());
        shown.push_back(format_short(v[p].is_number() ? format_number(v[p].get<double>()) : v[p].dump()));
      }
      *label = join(shown, "/");
      return v;
    };
    for (size_t i = 0; i < m.cv->ladder.size(); ++i) {
      MethodVariant mv = m;
      m.cv->apply(mv, m.cv->ladder[i]);
      std::string label = format_short(format_number(m.cv->ladder[i]));
      json values = parts.size() > 1 ? values_of(mv, &label) : json();
      std::vector<Metrics> sc;
      if (use_folds)
        for (const HoldoutSplit& h : *folds) sc.push_back(held_out_score(h, mv));
      else
        sc.push_back(held_out_score(*split, mv));
      const FoldSummary fs = summarize_folds(sc);
      json cand = {{"value", m.cv->ladder[i]},
                   {"holdout_rel_mse", fs.rel_mse_mean},
                   {"holdout_cos_rmse", fs.cos_rmse_mean}};
      if (values.is_object()) cand.update(values);
      cands.push_back(cand);
      words.push_back(label + ": " + format_short(format_number(fs.rel_mse_mean)));
      if (std::isfinite(fs.rel_mse_mean) && fs.rel_mse_mean < best_err) best_err = fs.rel_mse_mean, best = i;
      per_candidate.push_back(std::move(sc));
    }
    const double chosen = m.cv->ladder[best];
    const std::string by = use_folds ? std::to_string(folds->size()) + "-fold mean held-out rel_mse"
                                     : "held-out rel_mse of the held-out fraction";
    m.cv->apply(m, chosen);
    if (use_folds) chosen_folds = per_candidate[best];
    rec["cv"] = {{"key", m.cv->key}, {"by", by}, {"candidates", cands}, {"chosen", chosen},
                 {"seconds", since(tc)}};
    std::string chosen_label = format_short(format_number(chosen));
    if (parts.size() > 1) rec["cv"]["chosen_values"] = values_of(m, &chosen_label);
    cv_note = m.cv->key + " = \"cv\" chose " + chosen_label + " by " + by + " (" + join(words, ", ") + ")";
  }
  if (use_folds) {
    const auto tf = Clock::now();
    std::vector<Metrics> per_fold;
    json fr = json::array();
    for (size_t f = 0; f < folds->size(); ++f) {
      const HoldoutSplit& h = (*folds)[f];
      per_fold.push_back(chosen_folds.empty() ? held_out_score(h, m) : chosen_folds[f]);
      fr.push_back({{"train", h.train.valid_count()},
                    {"held", h.held.valid_count()},
                    {"holdout_rel_mse", per_fold.back().rel_mse},
                    {"holdout_cos_rmse", per_fold.back().cos_rmse}});
    }
    st.folds = summarize_folds(per_fold);
    st.folds_record = fr;
    st.folds_seconds = since(tf);
  }
  return st;
}

// Executes one run and writes its files and run.json; the caller writes the
// DONE marker (done_marker, write_done_marker). cache_notes: what was found
// wrong with caches this run would have used (rebuilt), for its notes.
RunEntry execute_run(const Plan& plan, const PlannedRun& pr, const SampleSet& samples, const fs::path& exp_dir,
                     RenderCache& renders, const json& build, const std::vector<std::string>& cache_notes) {
  const BrdfVariant& b = plan.brdfs[pr.brdf];
  const MethodKind& kind = *plan.methods[pr.method].impl;
  const fs::path run_dir = exp_dir / "runs" / pr.run_id;
  fs::remove_all(run_dir);
  fs::create_directories(run_dir);
  const auto wall0 = Clock::now();

  RunEntry e;
  e.run_id = pr.run_id;
  e.status = "ok";
  Row& row = e.row;
  set_presentation(row, plan, pr);
  json rec = run_record(plan, pr, samples);
  // Validation data: held-out samples or folds; the whole-domain set is shared by the BRDF's runs.
  HeldOutData hd = held_out_data(plan, pr, samples);
  const std::vector<HoldoutSplit>& folds = hd.folds;
  const std::optional<HoldoutSplit>& split = hd.split;
  const bool use_folds = !folds.empty();
  const SampleSet& fit_samples = split ? split->train : samples;
  // Symmetries (experiments/run/symmetry_prep.h): the fit sees each raw training
  // sample's orbit; the held-out split stays on the raw samples, and so do the
  // metrics unless the samples are their orbit's representatives (scored_set).
  const SymmetryChoice sym = choose_symmetries(plan.samplings[pr.sampling], samples);
  OrbitInfo orbit;
  // Kinds that tabulate the BRDF (svd, sh-k, sh-r) see a measured BRDF made of
  // the training samples only, so their held-out columns are on unseen data;
  // the whole-domain fill reads the same training-only BRDF.
  const FitPrep prep = prepare_fit(plan, pr, fit_samples, split.has_value(), sym, &orbit);
  const BrdfVariant& fit_b = prep.brdf;
  const FillChoice& fill = prep.fill;
  const SampleSet& fit_view = prep.view;
  if (plan.samplings[pr.sampling].kind == "measured") rec["fill"] = fill.describe();
  record_symmetries(sym, orbit, row, rec);
  std::string why_no_domain;
  const auto domain = b.brdf->whole_domain(&why_no_domain) ? renders.validation(plan, pr.brdf) : nullptr;
  const LogTransform lt = LogTransform::of(fit_samples, plan.experiment.metric_eps);
  MethodVariant m = with_tolerance_scorer(plan.methods[pr.method], plan, pr, renders, domain, lt);

  // Azimuthal-invariance test of the BRDF (factor/isotropy.h): results column `isotropic`.
  const IsotropyResult isotropy = test_isotropy(*b.brdf);
  row["isotropic"] = isotropy.isotropic ? "true" : "false";
  rec["isotropy"] = isotropy.describe();

  // Held-out fits: a key chosen by held-out error, the k folds.
  const HeldOutStage held = held_out_stage(plan, pr, kind, m, sym, isotropy, run_dir, renders,
                                           use_folds ? &folds : nullptr, split ? &*split : nullptr, rec);
  const std::optional<FoldSummary>& fold_summary = held.folds;

  // Scene-weighted fits (experiments/report/scene_weights.h): the kind fits the
  // weighted samples; rel_mse and the other metrics stay unweighted.
  std::optional<SampleSet> weighted;
  if (const auto wf = m.options.find("weight_fit"); wf != m.options.end())
    weighted = scene_weighted(fit_view, scene_pairs(*b.brdf, plan.scene), wf->at("floor").get<double>());
  const RunContext c{plan, pr, fit_b, m, weighted ? *weighted : fit_view, lt, isotropy, run_dir,
                     [&] { return renders.get(plan, pr.brdf); }};
  const auto t0 = Clock::now();
  MethodOutcome out = kind.run(c);
  const double seconds = since(t0);
  if (!out.result) throw std::runtime_error("method " + m.kind + " returned no factorization");
  const Metrics mt = scored_metrics(*out.result, fit_samples, sym, lt);
  if (weighted) row["scene_rel_mse"] = format_number(evaluate_metrics(*out.result, *weighted, lt).rel_mse);

  // The kind's columns (the required ones empty unless it fills them), then the common ones.
  for (const char* k : {"parameterization", "reciprocity", "terms", "texture_size"}) row[k] = "";
  kind.fill_row(c, out, row);
  std::vector<std::string> notes = out.notes;
  if (!held.cv_note.empty()) notes.insert(notes.begin(), held.cv_note);
  fill_common_columns(c, out, mt, seconds, row, notes, rec);
  if (!cache_notes.empty()) rec["cache_rebuilt"] = cache_notes;
  notes.insert(notes.end(), cache_notes.begin(), cache_notes.end());
  {  // Validation on data the fit never saw, and its flags.
    const auto tv = Clock::now();
    std::optional<SampleSet> orbit_of_held;
    const SampleSet* held_scored = split ? &scored_set(split->held, sym, orbit_of_held) : nullptr;
    ValidationScores vs = score_validation(*out.result, domain.get(), held_scored, lt);
    if (fold_summary) vs.holdout = true, vs.held = fold_summary->mean();
    std::string scheme = validation_scheme(plan, b, domain.get(), vs, split ? &*split : nullptr,
                                           fold_summary ? &*fold_summary : nullptr, samples.valid_count());
    if (sym.score_orbit) scheme += (scheme.empty() ? "" : "; ") + scored_over_orbit_note(sym);
    if (!domain && plan.experiment.validation_pairs != 0)
      scheme = "no whole-domain columns: " + why_no_domain + (scheme.empty() ? "" : "; " + scheme);
    fill_validation_columns(vs, mt.rel_mse, scheme, row, notes);
    rec["validation"] = {{"scheme", scheme}, {"seconds", since(tv)}};
    record_held_out(rec["validation"], vs, domain.get(), split ? &*split : nullptr, held);
  }

  if (plan.experiment.export_factors) kind.export_files(c, out);
  if (m.sampler)
    run_sampling(*out.result, isotropy.isotropic, plan.scene, plan.experiment.export_factors, run_dir, row, rec);
  if (plan.experiment.render || plan.scene.shade) {
    const auto original = renders.get(plan, pr.brdf);
    const SphereRender approx = render_sphere(*out.result, plan.scene);
    if (plan.experiment.render) {
      write_comparison_png(*original, approx, (run_dir / "sphere.png").string());
      // report.html's WebGL2 viewer data (experiments/report/viewer.h), for
      // every kind that declares a viewer (its result must have viewer data).
      if (plan.experiment.export_factors && kind.has_viewer())
        write_viewer_data(*out.result, *plan.brdfs[pr.brdf].brdf, *original, plan.scene, pr.run_id,
                          plan.brdfs[pr.brdf].label + " | " + row["label"] + " " + row["sweep"],
                          (run_dir / "viewer.js").string());
    }
    if (approx.nonfinite) notes.push_back(std::to_string(approx.nonfinite) + " non-finite pixels rendered as 0");
    if (plan.scene.shade) row["shade_rmse"] = format_number(shade_rmse(*original, approx));
  }
  out.notes.clear();
  kind.extra_outputs(c, out, row);
  notes.insert(notes.end(), out.notes.begin(), out.notes.end());
  for (const auto& [k, v] : out.record.items()) rec[k] = v;
  row["notes"] = join(notes, "; ");
  rec["notes"] = notes;
  rec["wall_seconds"] = since(wall0);
  rec["build"] = build;
  e.files = write_run_record(exp_dir, run_dir, pr.run_id, row, rec);
  e.record = rec;
  return e;
}

ExperimentOutput base_output(const Plan& plan, const std::string& dir, int shard, int shards) {
  ExperimentOutput o;
  o.dir = dir;
  o.experiment = {{"name", plan.experiment.name},
                  {"seed", plan.experiment.seed},
                  {"description", plan.experiment.description},
                  {"out", plan.experiment.out},
                  {"metric_eps", plan.experiment.metric_eps},
                  {"scene", plan.scene.identity()}};
  o.config_path = plan.config_path;
  o.config_text = plan.config_text;
  o.defines = plan.defines;
  o.plan_hash = plan.plan_hash;
  o.shard = shard;
  o.shards = shards;
  o.plan = json::array();
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const PlannedRun& r = plan.runs[i];
    o.plan.push_back({{"run_id", r.run_id},
                      {"shard", static_cast<int>(i % shards) + 1},
                      {"brdf", plan.brdfs[r.brdf].label},
                      {"sampling", plan.samplings[r.sampling].label},
                      {"method", describe_method(plan.methods[r.method])}});
  }
  return o;
}

// How execute_in_parallel ended: stopped_by is the signal (SIGINT/SIGTERM)
// that stopped it, 0 when every run finished; abandon when runs were still
// executing then (their threads are detached: the caller must end the process
// without returning, see run_experiment).
struct PoolEnd {
  int stopped_by = 0;
  bool abandon = false;
};

// The state of execute_in_parallel's pool; it outlives the call when workers
// are abandoned (detached).
struct PoolState {
  RenderCache renders;
  std::mutex mu;
  std::condition_variable cv;
  int free_slots = 0;
  size_t next = 0, done = 0;
  int busy = 0, exited = 0;  // workers inside a run; workers that returned
  bool closed = false;       // the snapshot of finished runs is taken: no run finishes after it
  std::vector<RunEntry> entries;
};

// The failed row of run r (its folder removed).
RunEntry failed_entry(const Plan& plan, const PlannedRun& r, const fs::path& exp_dir, const std::exception& ex) {
  std::error_code ec;
  fs::remove_all(exp_dir / "runs" / r.run_id, ec);
  RunEntry f;
  f.run_id = r.run_id;
  f.status = "failed";
  set_presentation(f.row, plan, r);
  f.row["status"] = "failed";
  const bool oom = dynamic_cast<const std::bad_alloc*>(&ex) != nullptr;  // never "std::bad_alloc" alone
  f.row["notes"] = std::string("failed: ") + (oom ? "out of memory" : ex.what());
  f.record = {{"run_id", r.run_id}, {"error", ex.what()}, {"method", plan.methods[r.method].options}};
  return f;
}

// The progress line of a finished run e (done of total, t0 its start, start the pool's).
void print_run_end(std::ostream& err, RunEntry& e, const std::string& run_id, size_t done, size_t total,
                   Clock::time_point t0, Clock::time_point start) {
  const double el = since(start);
  const double eta = done < total ? el / done * (total - done) : 0.0;
  err << "[" << done << "/" << total << "] " << (e.status == "ok" ? "done " : "FAILED ") << run_id << " in "
      << std::fixed << std::setprecision(1) << since(t0) << std::defaultfloat << " s";
  if (e.status == "ok") err << ", rel_mse " << e.row["rel_mse"];
  else err << ": " << e.row["notes"];
  err << " | elapsed " << hms(el) << ", eta " << hms(eta) << "\n";
}

// Executes the runs `todo` (plan indices, plan order) on `jobs` slots: each
// run holds min(jobs, its method's cores) slots (runner.h), progress on err.
// A signal (experiments/run/interrupt.h) stops taking new runs; entries then
// holds the finished ones (a snapshot, under the pool's lock).
PoolEnd execute_in_parallel(const Plan& plan, const std::vector<size_t>& todo, int jobs,
                            const std::map<std::string, std::shared_ptr<const SampleSet>>& samples,
                            const std::vector<std::vector<std::string>>& run_notes, const fs::path& exp_dir,
                            const json& build, const RunOptions& opt, std::ostream& err,
                            std::vector<RunEntry>& entries) {
  using State = PoolState;
  auto st = std::make_shared<State>();
  st->free_slots = jobs;
  st->entries = entries;
  const auto start = Clock::now();
  const size_t total = todo.size();
  auto work = [&plan, &todo, jobs, &samples, &run_notes, &exp_dir, &build, &opt, &err, start, total](State& s) {
    for (;;) {
      size_t i;
      int w;
      {
        std::unique_lock<std::mutex> lk(s.mu);
        if (s.next >= todo.size() || interrupt_signal()) return;
        // Take the next run in plan order once enough slots are free.
        s.cv.wait(lk, [&] {
          if (s.next >= todo.size() || interrupt_signal()) return true;
          const int need = std::min(jobs, plan.methods[plan.runs[todo[s.next]].method].cores);
          return s.free_slots >= need;
        });
        if (s.next >= todo.size() || interrupt_signal()) return;
        ++s.busy;
        i = todo[s.next++];
        w = std::min(jobs, plan.methods[plan.runs[i].method].cores);
        s.free_slots -= w;
        if (!opt.quiet)
          err << "start " << s.next << "/" << total << " " << plan.runs[i].run_id << " "
              << describe_run(plan, plan.runs[i]) << "\n";
      }
      const PlannedRun& r = plan.runs[i];
      const auto t0 = Clock::now();
      RunEntry e;
      auto failed = [&](const std::exception& ex) { return failed_entry(plan, r, exp_dir, ex); };
      std::string marker;  // the DONE marker of a run whose files are written
      try {
        e = execute_run(plan, r, *samples.at(r.samples_key), exp_dir, s.renders, build, run_notes[i]);
        marker = done_marker(exp_dir, r.run_id, e.files);
      } catch (const std::exception& ex) {
        std::error_code ec;
        fs::remove_all(exp_dir / "runs" / r.run_id, ec);
        e = RunEntry{};
        // Cancelled by a signal (RunOptions::cancel_on_signal): left empty, so
        // marked interrupted below with the runs not started.
        if (!(dynamic_cast<const Cancelled*>(&ex) && interrupt_signal())) e = failed(ex);
      }
      if (!marker.empty()) test_signal_at_run_end();
      e.shard = opt.shard;
      {
        std::unique_lock<std::mutex> lk(s.mu);
        // The run is finished (DONE) and listed ok together, under the lock
        // the tables' snapshot takes: once the snapshot is taken (a signal),
        // a run that ends stays unfinished, as the tables list it.
        const bool too_late = s.closed;
        if (!marker.empty() && !too_late) {
          try {
            write_done_marker(exp_dir / "runs" / r.run_id, marker);
          } catch (const std::exception& ex) {
            e = failed(ex);
          }
        }
        if (!too_late) s.entries[i] = std::move(e);
        s.free_slots += w;
        --s.busy;
        ++s.done;
        if (!opt.quiet && !too_late) print_run_end(err, s.entries[i], r.run_id, s.done, total, t0, start);
      }
      s.cv.notify_all();
    }
  };
  PoolEnd end;
  std::vector<std::thread> pool;
  const int n_threads = std::min<int>(jobs, static_cast<int>(todo.size()));
  for (int t = 0; t < n_threads; ++t)
    pool.emplace_back([st, work] {
      work(*st);
      {
        std::unique_lock<std::mutex> lk(st->mu);
        ++st->exited;
      }
      st->cv.notify_all();
    });
  {
    std::unique_lock<std::mutex> lk(st->mu);
    while (st->exited < n_threads && !interrupt_signal()) st->cv.wait_for(lk, std::chrono::milliseconds(100));
    end.stopped_by = st->exited < n_threads || st->done < total ? interrupt_signal() : 0;
    if (end.stopped_by) {
      st->cv.notify_all();  // idle workers see the signal and return
      end.abandon = st->busy > 0 && !cancel_requested();  // cancelled runs end soon: wait
      if (!end.abandon)
        while (st->exited < n_threads) st->cv.wait_for(lk, std::chrono::milliseconds(100));
    }
    entries = st->entries;  // a snapshot: abandoned workers finish no run after it
    st->closed = true;
    if (end.stopped_by) note_finished_runs_taken();
  }
  for (auto& t : pool) {
    if (end.abandon) t.detach();  // the process ends without returning (run_experiment, _Exit)
    else t.join();
  }
  return end;
}

enum class Action { Run, Redo, Cached, Forced, OtherShard };

// The cache key is the config, not the code: says when reused runs come from
// another build (git commit of the source tree), so results that a fitter
// change would alter are not mixed in silently.
void warn_other_builds(const Plan& plan, const std::vector<Action>& action,
                       const std::vector<std::optional<RunEntry>>& cached, const json& build, size_t n_cached,
                       RunSummary& sum, std::ostream& err) {
  std::set<std::string> other_commits;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    if (action[i] != Action::Cached) continue;
    const std::string theirs = cached_run_commit(cached[i]->record);
    if (build.contains("git_commit") && theirs != build["git_commit"].get<std::string>()) {
      ++sum.cached_other_build;
      other_commits.insert(theirs.empty() ? "unrecorded" : theirs);
    }
  }
  if (sum.cached_other_build)
    err << "brdf-factor: warning: " << sum.cached_other_build << " of " << n_cached
        << " cached runs were made by another build (" << join(std::vector<std::string>(other_commits.begin(), other_commits.end()), ", ")
        << "; this build " << build["git_commit"].get<std::string>()
        << "): the cache does not see code changes, --force redoes them\n";
}

// The --dry-run listing: every run of the plan with what would happen to it.
void print_dry_run(const Plan& plan, const std::vector<Action>& action, const std::string& dir,
                   const RunOptions& opt, size_t n_run, size_t n_cached, size_t n_other, std::ostream& out) {
  out << "experiment " << plan.experiment.name << ": " << plan.runs.size() << " runs (" << plan.brdfs.size()
      << " brdf x " << plan.samplings.size() << " sampling x " << plan.methods.size() << " method variants";
  if (plan.duplicates) out << "; " << plan.duplicates << " duplicate combinations kept once";
  out << ") -> " << dir << "\n";
  if (opt.shards > 1) out << "shard " << opt.shard << "/" << opt.shards << "\n";
  static const char* names[] = {"run", "redo", "cached", "force", "other-shard"};
  for (size_t i = 0; i < plan.runs.size(); ++i)
    out << plan.runs[i].run_id << "  " << std::left << std::setw(11) << names[static_cast<int>(action[i])]
        << " " << describe_run(plan, plan.runs[i]) << "\n";
  out << "would run " << n_run << ", skip " << n_cached << " cached (--force redoes them) and " << n_other
      << " of other shards\n";
}

// The samples of the runs to do, by sample key (cache/samples/ in the folder);
// a cache entry that was refused and rebuilt is warned about on err and its
// problem kept in `rebuilt` (by sample key) for the notes of its runs.
std::map<std::string, std::shared_ptr<const SampleSet>> prepare_samples(const Plan& plan,
                                                                        const std::vector<Action>& action,
                                                                        const fs::path& exp_dir,
                                                                        const RunOptions& opt, std::ostream& err,
                                                                        std::map<std::string, std::string>& rebuilt) {
  std::map<std::string, std::shared_ptr<const SampleSet>> samples;
  const fs::path cache_dir = exp_dir / "cache" / "samples";
  fs::create_directories(cache_dir);
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const PlannedRun& r = plan.runs[i];
    if (action[i] == Action::Cached || action[i] == Action::OtherShard || samples.count(r.samples_key)) continue;
    const auto t0 = Clock::now();
    bool hit = false;
    std::string problem;
    samples[r.samples_key] = make_samples(plan, r, cache_dir, opt.force, &hit, &problem);
    if (!problem.empty()) {
      err << "brdf-factor: warning: sample cache " << problem << ": not trusted, resampled\n";
      rebuilt[r.samples_key] = problem;
    }
    if (!opt.quiet)
      err << "samples: " << plan.brdfs[r.brdf].label << " | " << plan.samplings[r.sampling].label << ": "
          << samples[r.samples_key]->summary() << (hit ? " (cached)" : "") << " in " << hms(since(t0)) << "\n";
  }
  return samples;
}

// What each run of this shard needs: cached runs' entries go to `cached`,
// this shard's run ids and count to `sum`. A finished run that fails
// verification (load_done_run) is redone: warned about on err, its problem
// kept in `untrusted` (by plan index) for its notes.
std::vector<Action> decide_actions(const Plan& plan, const fs::path& exp_dir, const RunOptions& opt,
                                   RunSummary& sum, std::vector<std::optional<RunEntry>>& cached,
                                   std::vector<std::string>& untrusted, std::ostream& err) {
  std::vector<Action> action(plan.runs.size());
  untrusted.assign(plan.runs.size(), "");
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const PlannedRun& r = plan.runs[i];
    if (static_cast<int>(i % opt.shards) != opt.shard - 1) {
      action[i] = Action::OtherShard;
      continue;
    }
    sum.run_ids.push_back(r.run_id);
    ++sum.in_shard;
    cached[i] = load_done_run(exp_dir, r.run_id, &untrusted[i]);
    if (cached[i]) action[i] = opt.force ? Action::Forced : Action::Cached;
    else action[i] = incomplete_folder(exp_dir, r.run_id) ? Action::Redo : Action::Run;
    if (!untrusted[i].empty())
      err << "brdf-factor: warning: run " << r.run_id << ": " << untrusted[i] << ": not trusted, the run is redone\n";
  }
  return action;
}

// The line saying what this run of the experiment will do (runs to do and
// cached, those redone and not trusted, job slots, folder).
void print_start(const Plan& plan, const std::vector<Action>& action, const std::vector<std::string>& untrusted,
                 const RunSummary& sum, const RunOptions& opt, size_t n_run, size_t n_cached, int jobs,
                 const std::string& dir, std::ostream& err) {
  err << "experiment " << plan.experiment.name << ": " << sum.in_shard << " runs";
  if (opt.shards > 1) err << " in shard " << opt.shard << "/" << opt.shards << " (of " << plan.runs.size() << ")";
  err << ": " << n_run << " to do, " << n_cached << " cached";
  size_t redo = 0, untrusted_runs = 0;
  for (size_t i = 0; i < action.size(); ++i) {
    redo += action[i] == Action::Redo;
    untrusted_runs += !untrusted[i].empty();
  }
  if (redo)
    err << " (" << redo << " unfinished"
        << (untrusted_runs ? ", " + std::to_string(untrusted_runs) + " of them not trusted" : std::string())
        << ", redone)";
  err << "; " << jobs << " job slot" << (jobs > 1 ? "s" : "") << " -> " << dir << "\n";
}

// What was found wrong with the caches each run would have used (its notes):
// an untrusted finished run (by plan index), rebuilt samples (by sample key).
std::vector<std::vector<std::string>> cache_notes(const Plan& plan, const std::vector<std::string>& untrusted,
                                                  const std::map<std::string, std::string>& rebuilt) {
  std::vector<std::vector<std::string>> run_notes(plan.runs.size());
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    if (!untrusted[i].empty()) run_notes[i].push_back("redone: " + untrusted[i] + " (not trusted)");
    if (auto it = rebuilt.find(plan.runs[i].samples_key); it != rebuilt.end())
      run_notes[i].push_back("samples rebuilt: " + it->second + " (not trusted)");
  }
  return run_notes;
}

// Marks the runs a signal stopped before they finished; returns their count.
size_t mark_interrupted(const Plan& plan, const std::vector<size_t>& todo, int stopped_by, int shard,
                        std::vector<RunEntry>& entries) {
  size_t unfinished = 0;
  for (size_t i : todo) {
    if (!entries[i].run_id.empty()) continue;
    ++unfinished;
    RunEntry& e = entries[i];
    e.run_id = plan.runs[i].run_id;
    e.status = "interrupted";
    e.shard = shard;
    set_presentation(e.row, plan, plan.runs[i]);
    e.row["status"] = "interrupted";
    e.row["notes"] = "interrupted by " + signal_name(stopped_by) + " before it finished; the next run does it";
    e.record = {{"run_id", e.run_id}, {"error", "interrupted"}, {"method", plan.methods[plan.runs[i].method].options}};
  }
  return unfinished;
}

// After the outputs are written: the error naming the first failed run.
[[noreturn]] void throw_failed_runs(const RunSummary& sum, const std::vector<RunEntry>& runs) {
  std::string first;
  for (const auto& r : runs)
    if (r.status != "ok") {
      first = r.run_id + ": " + r.row.at("notes");
      break;
    }
  throw std::runtime_error(std::to_string(sum.failed) + " of " + std::to_string(sum.in_shard) +
                           " runs failed (first: " + first + "); they are marked in " + sum.files.results_md +
                           " and will be redone by the next run");
}

}  // namespace

void print_output_paths(std::ostream& out, const OutputFiles& f) {
  out << "results: " << f.results_md << "\n";
  out << "report:  " << f.report << "\n";
}

void parse_shard(const std::string& text, int& k, int& n) {
  const auto slash = text.find('/');
  auto bad = [&] {
    return std::invalid_argument("--shard: expected K/N with 1 <= K <= N (e.g. 2/8), found '" + text + "'");
  };
  if (slash == std::string::npos) throw bad();
  const std::string a = text.substr(0, slash), b = text.substr(slash + 1);
  if (a.empty() || b.empty() || a.find_first_not_of("0123456789") != std::string::npos ||
      b.find_first_not_of("0123456789") != std::string::npos || a.size() > 6 || b.size() > 6)
    throw bad();
  k = std::stoi(a);
  n = std::stoi(b);
  if (n < 1 || k < 1 || k > n) throw bad();
}

RunSummary run_experiment(const RunOptions& opt, std::ostream& out, std::ostream& err) {
  if (opt.shards < 1 || opt.shard < 1 || opt.shard > opt.shards)
    throw std::invalid_argument("--shard: expected K/N with 1 <= K <= N, found " + std::to_string(opt.shard) + "/" +
                                std::to_string(opt.shards));
  const Plan plan = load_plan(opt.config, opt.defines);
  RunSummary sum;
  std::string dir = opt.out.empty() ? plan.experiment.out : opt.out;
  if (opt.out.empty() && opt.shards > 1)
    dir = (fs::path(dir) / ("shard-" + std::to_string(opt.shard) + "-of-" + std::to_string(opt.shards))).string();
  sum.out_dir = dir;
  sum.planned = plan.runs.size();
  const fs::path exp_dir(dir);
  // One writer per output folder, held from before the cache is read until the tables are written.
  std::optional<OutdirLock> lock;
  std::optional<InterruptScope> interrupt_scope;  // SIGINT/SIGTERM stop cleanly (experiments/run/interrupt.h)
  if (!opt.dry_run) {
    lock.emplace(dir, "run " + opt.config);
    interrupt_scope.emplace(opt.cancel_on_signal);
  }

  std::vector<std::optional<RunEntry>> cached(plan.runs.size());
  std::vector<std::string> untrusted;
  const std::vector<Action> action = decide_actions(plan, exp_dir, opt, sum, cached, untrusted, err);
  size_t n_run = 0, n_cached = 0, n_other = 0;
  for (Action a : action) {
    if (a == Action::Cached) ++n_cached;
    else if (a == Action::OtherShard) ++n_other;
    else ++n_run;
  }

  const json build = build_identity(software_versions());
  warn_other_builds(plan, action, cached, build, n_cached, sum, err);

  if (opt.dry_run) {
    print_dry_run(plan, action, dir, opt, n_run, n_cached, n_other, out);
    return sum;
  }

  {  // Before any work: the folder is writable and has room (experiments/run/preflight.h).
    std::vector<bool> todo_runs(plan.runs.size());
    for (size_t i = 0; i < plan.runs.size(); ++i)
      todo_runs[i] = action[i] != Action::Cached && action[i] != Action::OtherShard;
    check_output_folder(dir, estimate_output_bytes(plan, todo_runs));
  }
  fs::create_directories(exp_dir / "runs");
  const int jobs_cfg = opt.jobs >= 0 ? opt.jobs : plan.experiment.jobs;
  const int jobs = hardware_threads(jobs_cfg);
  if (!opt.quiet) print_start(plan, action, untrusted, sum, opt, n_run, n_cached, jobs, dir, err);

  // Samples for the runs to do.
  std::map<std::string, std::string> rebuilt;
  const auto samples = prepare_samples(plan, action, exp_dir, opt, err, rebuilt);
  const std::vector<std::vector<std::string>> run_notes = cache_notes(plan, untrusted, rebuilt);

  // Execute.
  std::vector<RunEntry> entries(plan.runs.size());
  std::vector<size_t> todo;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    if (action[i] == Action::Cached) {
      entries[i] = *cached[i];
      set_presentation(entries[i].row, plan, plan.runs[i]);
    } else if (action[i] != Action::OtherShard) {
      todo.push_back(i);
    }
  }
  const auto start = Clock::now();
  const PoolEnd pool_end =
      execute_in_parallel(plan, todo, jobs, samples, run_notes, exp_dir, build, opt, err, entries);
  const int stopped_by = pool_end.stopped_by;
  const size_t unfinished = stopped_by ? mark_interrupted(plan, todo, stopped_by, opt.shard, entries) : 0;

  ExperimentOutput o = base_output(plan, dir, opt.shard, opt.shards);
  o.plots = opt.plots && plan.experiment.plots;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    if (action[i] == Action::OtherShard) continue;
    entries[i].shard = entries[i].shard ? entries[i].shard : opt.shard;
    if (entries[i].status == "ok") {
      if (action[i] == Action::Cached) ++sum.cached;
      else ++sum.executed;
      if (action[i] == Action::Redo) ++sum.redone;
    } else if (entries[i].status != "interrupted") {
      ++sum.failed;
    }
    o.runs.push_back(entries[i]);
  }
  sum.files = write_experiment_outputs(o, opt.quiet ? nullptr : &err);
  if (!opt.quiet)
    err << "experiment " << plan.experiment.name << ": " << sum.executed << " run, " << sum.cached
        << " cached, " << sum.failed << " failed in " << hms(since(start)) << "\n";
  if (stopped_by) {
    const std::string msg = "interrupted by " + signal_name(stopped_by) + ": " +
                            std::to_string(sum.in_shard - unfinished) + " of " + std::to_string(sum.in_shard) +
                            " runs are finished and written to " + sum.files.results_md + ", " +
                            std::to_string(unfinished) +
                            " are not (marked interrupted); run the same command again to resume "
                            "(finished runs are reused)";
    if (pool_end.abandon) {  // runs still executing on detached threads: end the process here
      err << "brdf-factor: " << msg << "\n";
      err.flush();
      std::fflush(nullptr);
      std::_Exit(128 + stopped_by);
    }
    throw Interrupted(msg, stopped_by);
  }
  print_output_paths(out, sum.files);
  if (sum.failed) throw_failed_runs(sum, o.runs);
  if (const std::string p = plot_failure(sum.files); !p.empty()) throw std::runtime_error(p);  // tables written
  return sum;
}

}  // namespace bf
