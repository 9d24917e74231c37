// Experiment runner (see runner.h).
#include "experiments/runner.h"

#include "brdfs/safe_path.h"
#include "experiments/interrupt.h"
#include "experiments/outdir_lock.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <unistd.h>

#include "brdfs/sample_csv.h"
#include "brdfs/sampleset.h"
#include "experiments/cli_util.h"
#include "experiments/render.h"
#include "experiments/preflight.h"
#include "factor/export.h"
#include "factor/isotropy.h"
#include "factor/lighting.h"
#include "factor/metrics.h"
#include "factor/model_fit.h"
#include "factor/refine.h"
#include "factor/size_select.h"
#if __has_include("brdfs/measured.h")
#include "brdfs/measured.h"
#define BF_HAVE_MEASURED 1
#endif
#include "brdfs/merl.h"

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

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

// ------------------------------------------------------------------ sample cache

// Binary sample cache: magic, count, flags, then the arrays. Any mismatch on
// reading (size, magic, counts) makes the cache entry unusable (resampled).
constexpr char kSampleMagic[8] = {'B', 'F', 'S', 'A', 'M', 'P', '0', '1'};

void write_samples_bin(const SampleSet& s, const std::string& path) {
  write_file_atomic(path, [&](std::ostream& o) {
    auto put64 = [&](uint64_t v) { o.write(reinterpret_cast<const char*>(&v), sizeof v); };
    o.write(kSampleMagic, 8);
    const uint64_t n = s.size();
    put64(n);
    put64(s.weight.empty() ? 0 : 1);
    put64(s.invalid_value);
    put64(s.invalid_horizon);
    put64(s.invalid_weight);
    put64(s.description.size());
    o.write(s.description.data(), static_cast<std::streamsize>(s.description.size()));
    for (const auto* arr : {&s.wi, &s.wo})
      for (const Vec3& v : *arr) o.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(double));
    for (const Rgb& v : s.value) o.write(reinterpret_cast<const char*>(v.data()), 3 * sizeof(double));
    if (!s.weight.empty()) o.write(reinterpret_cast<const char*>(s.weight.data()), n * sizeof(double));
    o.write(reinterpret_cast<const char*>(s.valid.data()), static_cast<std::streamsize>(n));
  });
}

bool read_samples_bin(const std::string& path, SampleSet& s) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::error_code ec;
  const uint64_t file_size = fs::file_size(path, ec);
  if (ec) return false;
  char magic[8];
  if (!in.read(magic, 8) || std::memcmp(magic, kSampleMagic, 8) != 0) return false;
  uint64_t h[6];
  if (!in.read(reinterpret_cast<char*>(h), sizeof h)) return false;
  const uint64_t n = h[0], has_w = h[1], dlen = h[5];
  if (n > 200'000'000 || has_w > 1 || dlen > 1'000'000) return false;
  const uint64_t expect = 8 + sizeof h + dlen + n * (9 * sizeof(double) + (has_w ? sizeof(double) : 0) + 1);
  if (expect != file_size) return false;
  s = SampleSet{};
  s.description.resize(dlen);
  in.read(s.description.data(), static_cast<std::streamsize>(dlen));
  s.wi.resize(n);
  s.wo.resize(n);
  s.value.resize(n);
  for (auto* arr : {&s.wi, &s.wo})
    for (Vec3& v : *arr) in.read(reinterpret_cast<char*>(v.data()), 3 * sizeof(double));
  for (Rgb& v : s.value) in.read(reinterpret_cast<char*>(v.data()), 3 * sizeof(double));
  if (has_w) {
    s.weight.resize(n);
    in.read(reinterpret_cast<char*>(s.weight.data()), n * sizeof(double));
  }
  s.valid.resize(n);
  in.read(reinterpret_cast<char*>(s.valid.data()), static_cast<std::streamsize>(n));
  if (!in) return false;
  s.invalid_value = h[2];
  s.invalid_horizon = h[3];
  s.invalid_weight = h[4];
  return true;
}

std::shared_ptr<const SampleSet> make_samples(const Plan& plan, const PlannedRun& r, const fs::path& cache_dir,
                                              bool force, bool* from_cache) {
  const BrdfVariant& b = plan.brdfs[r.brdf];
  const SamplingVariant& s = plan.samplings[r.sampling];
  *from_cache = false;
  auto out = std::make_shared<SampleSet>();
  if (s.kind == "file") {
    *out = read_sample_csv(s.path);
    return out;
  }
  if (s.kind == "measured") {
#ifdef BF_HAVE_MEASURED
    *out = measured_samples(*b.brdf);
    return out;
#else
    throw std::invalid_argument("sampling: measured samples are not available in this build");
#endif
  }
  const fs::path path = cache_dir / (r.samples_key + ".bin");
  if (!force && read_samples_bin(path.string(), *out)) {
    *from_cache = true;
    return out;
  }
  if (s.kind == "grid") *out = sample_grid(*b.brdf, s.resolution);
  else *out = sample_stratified(*b.brdf, s.count, s.seed);
  write_samples_bin(*out, path.string());
  return out;
}

// ------------------------------------------------------------------ one run


// How a tabulating method (svd, sh-k, sh-r) reads `brdf` when it is measured
// data: the interpolation between measurements; "" for analytic BRDFs.
std::string resampling_note(const Brdf& brdf) {
#ifdef BF_HAVE_MEASURED
  if (const auto* mb = dynamic_cast<const MeasuredBrdf*>(&brdf))
    return "resampled: tabulated from the modified Shepard interpolant (k = " +
           std::to_string(mb->options().neighbours) + ", Marschner space) of " +
           std::to_string(mb->samples().size()) + " measured samples";
#endif
  if (const auto* mb = dynamic_cast<const MerlBrdf*>(&brdf))
    return std::string("resampled: tabulated from the MERL table by ") +
           (mb->lookup() == MerlLookup::Linear ? "trilinear interpolation of bin centres" : "nearest bin");
  return "";
}

std::string describe_method(const MethodVariant& m) {
  static const std::map<std::string, std::vector<std::string>> shown = {
      {"mccool", {"texture_size"}},
      {"fit", {"terms", "texture_size", "parameterization", "reciprocity"}},
      {"search", {"parameterization", "terms", "texture_size", "reciprocity", "restarts", "optimizer",
                  "beam", "backfit_sweeps", "seed"}},
      {"svd", {"terms", "texture_size", "parameterization", "log"}},
      {"sh-k", {"order", "texture_size"}},
      {"sh-r", {"order", "view_order"}},
      {"model-fit", {"model", "metric", "anisotropic", "lobes", "starts", "seed"}},
  };
  std::string s = m.label;
  if (m.label != m.kind) s += " (" + m.kind + ")";
  for (const auto& k : shown.at(m.kind))
    if (m.options.contains(k)) {
      const json& v = m.options[k];
      if (k == "order" && m.kind == "sh-r" && v.get<int>() < 0) continue;
      if (k == "view_order" && v.get<int>() < 0) continue;
      s += " " + k + "=" + (v.is_string() ? v.get<std::string>() : v.dump());
    }
  if (m.tolerance) s += " tolerance=" + m.tolerance->metric + "<=" + format_number(m.tolerance->value);
  if (m.refine != "none") s += " refine=" + m.refine;
  return s;
}

std::string describe_run(const Plan& plan, const PlannedRun& r) {
  return plan.brdfs[r.brdf].label + " | " + plan.samplings[r.sampling].label + " | " +
         describe_method(plan.methods[r.method]);
}

// Original-BRDF renders are shared by every run of a BRDF.
class RenderCache {
 public:
  std::shared_ptr<const SphereRender> get(const Plan& plan, size_t brdf) {
    std::unique_lock<std::mutex> lk(mu_);
    auto& slot = map_[brdf];
    if (!slot) slot = std::make_shared<SphereRender>(render_sphere(*plan.brdfs[brdf].brdf, plan.scene));
    return slot;
  }

 private:
  std::mutex mu_;
  std::map<size_t, std::shared_ptr<const SphereRender>> map_;
};

std::vector<std::string> list_files(const fs::path& exp_dir, const fs::path& run_dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(run_dir))
    if (e.is_regular_file()) {
      const std::string name = e.path().filename().string();
      if (name == "DONE" || name[0] == '.') continue;
      files.push_back(fs::relative(e.path(), exp_dir).generic_string());
    }
  std::sort(files.begin(), files.end());
  return files;
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

RunEntry execute_run(const Plan& plan, const PlannedRun& pr, const SampleSet& samples, const fs::path& exp_dir,
                     RenderCache& renders, const json& build) {
  const BrdfVariant& b = plan.brdfs[pr.brdf];
  const SamplingVariant& s = plan.samplings[pr.sampling];
  const MethodVariant& m = plan.methods[pr.method];
  const fs::path run_dir = exp_dir / "runs" / pr.run_id;
  fs::remove_all(run_dir);
  fs::create_directories(run_dir);
  const auto wall0 = Clock::now();

  RunEntry e;
  e.run_id = pr.run_id;
  e.status = "ok";
  Row& row = e.row;
  set_presentation(row, plan, pr);
  json seeds = {{"experiment", plan.experiment.seed}};
  if (s.kind == "stratified") seeds["sampling"] = s.seed;
  if (m.kind == "search" || m.kind == "model-fit") seeds["method"] = m.seed;
  json rec = {{"run_id", pr.run_id},
              {"identity", pr.identity},
              {"brdf", {{"label", b.label}, {"eval", b.brdf->to_string()}}},
              {"sampling", s.label},
              {"samples_description", samples.summary()},
              {"method", m.options},
              {"execution", m.execution},
              {"seeds", seeds}};
  std::vector<std::string> notes;

  FactorizationPtr f;
  std::shared_ptr<const HomomorphicFactorization> h;
  std::vector<double> errs;
  int evaluations = 0;
  std::optional<SizeChoice> choice;
  const LogTransform lt = LogTransform::of(samples, plan.experiment.metric_eps);

  // Azimuthal-invariance test of the BRDF (factor/isotropy.h): results column `isotropic`.
  const IsotropyResult isotropy = test_isotropy(*b.brdf);
  row["isotropic"] = isotropy.isotropic ? "true" : "false";
  rec["isotropy"] = isotropy.describe();

  const auto t0 = Clock::now();
  // With texture_size = "auto", the tolerance picks the resolution from the
  // ladder too (factor/size_select.h); otherwise the ladder is the one size.
  const std::vector<int> ladder = m.texture_ladder.empty() ? std::vector<int>{m.texture_size} : m.texture_ladder;
  if (m.kind == "mccool") {
    const FitData data(samples, m.fit.eps);
    if (m.tolerance) {
      choice = select_homomorphic_size(data, samples, lt, mccool_terms, 2, 2, m.fit, "mccool", *m.tolerance, ladder);
      h = std::dynamic_pointer_cast<const HomomorphicFactorization>(choice->result);
      errs = choice->errors_after_term;
    } else {
      h = fit_homomorphic(data, mccool_terms(m.texture_size), m.fit, "mccool", &errs);
    }
  } else if (m.kind == "fit") {
    const FitData data(samples, m.fit.eps);
    if (m.tolerance) {
      const auto terms_at = [&](int res) { return terms_at_resolution(m.projections, res); };
      choice = select_homomorphic_size(data, samples, lt, terms_at, 1, m.cap, m.fit, "fit", *m.tolerance, ladder);
      h = std::dynamic_pointer_cast<const HomomorphicFactorization>(choice->result);
      errs = choice->errors_after_term;
    } else {
      h = fit_homomorphic(data, std::vector<TermSpec>(m.projections.begin(), m.projections.begin() + m.terms),
                          m.fit, "fit", &errs);
    }
  } else if (m.kind == "search") {
    const FitData data(samples, m.fit.eps);
    SearchOptions so = m.search;
    SizeChoice c;  // with a tolerance: the terms tried, filled as the search goes
    if (m.tolerance) {
      // The greedy search stops at the first term whose refit reaches the
      // target (search/term_search.h, stop_after_term); later terms are never searched.
      c.method = "search";
      c.knob = "terms";
      c.metric = m.tolerance->metric;
      so.stop_after_term = [&](const HomomorphicFactorization& hf) {
        const double v = metric_value(evaluate_metrics(hf, samples, lt), c.metric);
        c.tried.push_back({static_cast<int>(hf.terms().size()), -1, v});
        c.value = static_cast<int>(hf.terms().size());
        c.error = v;
        c.reached = v <= m.tolerance->value;
        return c.reached;
      };
    }
    SearchResult sr = search_factorization(data, so);
    if (m.tolerance) {
      c.seconds = sr.seconds;
      c.result = sr.factorization;
      c.errors_after_term = sr.rel_mse_after_term;
      choice = c;
    }
    h = sr.factorization;
    errs = sr.rel_mse_after_term;
    evaluations = sr.evaluations;
    json terms = json::array();
    for (const auto& t : sr.terms)
      terms.push_back({{"rotation", t.rotation},
                       {"search_rel_mse", std::isfinite(t.search_rel_mse) ? json(t.search_rel_mse) : json()},
                       {"evaluations", t.evaluations},
                       {"seconds", t.seconds},
                       {"best_start", t.best_start},
                       {"backfit_evaluations", t.backfit_evaluations},
                       {"backfit_moves", t.backfit_moves}});
    rec["terms"] = terms;
    if (sr.beam_rel_mse.size() > 1) {
      rec["beam_rel_mse"] = sr.beam_rel_mse;
      rec["best_branch"] = sr.best_branch;
    }
  } else if (m.kind == "svd") {
    if (m.tolerance && !m.texture_ladder.empty())
      choice = select_svd_size(*b.brdf, samples, m.svd, *m.tolerance, m.cap, m.texture_ladder);
    else if (m.tolerance)
      choice = select_svd_rank(*b.brdf, samples, m.svd, *m.tolerance, m.cap);
    else
      f = fit_svd(*b.brdf, m.svd);
  } else if (m.kind == "sh-k") {
    // An isotropic BRDF (by the azimuthal-invariance test) is stored along phi_v = 0 only.
    ShkOptions ko = m.shk;
    ko.reduced = m.options.value("reduce_isotropic", false) && isotropy.isotropic;
    if (m.tolerance) choice = select_shk_order(*b.brdf, samples, ko, *m.tolerance, m.cap);
    else f = fit_shk(*b.brdf, ko);
  } else if (m.kind == "sh-r") {
    if (m.tolerance) choice = select_shr_orders_by_metric(*b.brdf, samples, m.shr, *m.tolerance);
    else f = fit_shr(*b.brdf, m.shr);
  } else if (m.kind == "model-fit") {
    auto mf = std::make_shared<ModelFitFactorization>(fit_model(samples, m.model_fit));
    const ModelFitResult& res = mf->result();
    json params = json::object();
    for (const auto& [k, v] : res.parameters) params[k] = v;
    rec["model_fit"] = {{"spec", res.spec}, {"parameters", params}, {"cost", res.cost},
                        {"best_start", res.best_start}, {"start_costs", res.start_costs},
                        {"iterations", res.iterations}};
    evaluations = res.iterations;
    f = mf;
  }
  // Refinement (factor/refine.h) of a homomorphic fit: the row reports the
  // refined factorization, the *_before columns the fit it started from.
  Metrics before;
  double refine_seconds = 0;
  if (h && m.refine != "none") {
    before = evaluate_metrics(*h, samples, lt);
    const auto tr = Clock::now();
    RefineReport rep;
    try {
      h = refine(*h, samples, m.refine_options, &rep);
      rec["refinement"] = {{"objective", rep.objective},        {"linear_solver", rep.linear_solver},
                           {"iterations", rep.iterations},      {"seconds", rep.seconds},
                           {"initial_cost", rep.initial_cost},  {"final_cost", rep.final_cost},
                           {"termination", rep.termination},    {"parameters", rep.parameters},
                           {"residuals", rep.residuals},        {"texels_added", rep.texels_added},
                           {"blend_weight", m.refine_options.blend_weight},
                           {"smoothing", m.refine_options.smoothing}};
    } catch (const std::runtime_error& ex) {
      // Ceres found no finite solution: the start is the best answer.
      notes.push_back(std::string("refinement failed, unrefined fit kept: ") + ex.what());
      rec["refinement"] = {{"failed", ex.what()}};
    }
    refine_seconds = since(tr);
  }
  const double seconds = since(t0);
  if (h) f = h;
  if (choice && !f) f = choice->result;
  if (!f) throw std::runtime_error("method " + m.kind + " returned no factorization");

  const Metrics mt = evaluate_metrics(*f, samples, lt);

  // Kind-specific columns.
  row["parameterization"] = "";
  row["reciprocity"] = "";
  row["terms"] = "";
  row["texture_size"] = "";
  if (h) {
    std::vector<std::string> params;
    size_t recip = 0, symmetric = 0;
    for (const auto& t : h->terms()) {
      if (std::find(params.begin(), params.end(), to_string(t.proj.param)) == params.end())
        params.push_back(to_string(t.proj.param));
      recip += t.reciprocal;
      symmetric += t.reciprocal || t.proj.self_conjugate();
    }
    row["parameterization"] = join(params, "+");
    // true: every term is read through its conjugate or is its own conjugate
    // (McCool's p(h) texture), so the approximation is reciprocal.
    row["reciprocity"] = recip == 0 ? "false" : symmetric == h->terms().size() ? "true" : "mixed";
    row["terms"] = std::to_string(h->terms().size());
    row["texture_size"] = std::to_string(choice && choice->texture_size ? choice->texture_size : m.texture_size);
    std::vector<std::string> ec;
    for (double v : errs) ec.push_back(format_number(v));
    row["errors_after_term"] = join(ec, ";");
    rec["reconstruction"] = h->subtract_eps() ? "A exp(s) - eps A, clamped at 0" : "A exp(s)";
    if (m.refine != "none") {
      row["refine"] = m.refine;
      row["refine_seconds"] = format_number(std::round(refine_seconds * 1000.0) / 1000.0);
      const std::pair<const char*, double> cells[] = {
          {"rel_mse_before", before.rel_mse},   {"rel_mae_before", before.rel_mae},
          {"rel_max_before", before.rel_max},   {"lin_rmse_before", before.lin_rmse},
          {"lin_mae_before", before.lin_mae},   {"lin_max_before", before.lin_max},
          {"cos_rmse_before", before.cos_rmse}};
      for (const auto& [k, v] : cells) row[k] = format_number(v);
    }
  } else if (auto svd = std::dynamic_pointer_cast<const SvdFactorization>(f)) {
    row["parameterization"] = to_string(svd->options().param);
    row["terms"] = std::to_string(svd->rank());
    row["texture_size"] = std::to_string(svd->options().res);
    row["negative_texels"] = std::to_string(svd->negative_texels());
    std::vector<std::string> ec;
    for (int k = 1; k <= svd->rank(); ++k)
      ec.push_back(format_number(evaluate_metrics(*svd->truncated(k), samples, lt).rel_mse));
    row["errors_after_term"] = join(ec, ";");
  } else if (auto shk = std::dynamic_pointer_cast<const ShkFactorization>(f)) {
    row["texture_size"] = std::to_string(shk->options().view_res);
    row["order"] = std::to_string(shk->order());
    if (shk->negative_fraction > 0)
      notes.push_back("ringing: product negative at " + format_short(format_number(100.0 * shk->negative_fraction)) +
                      "% of the quadrature nodes");
  } else if (auto shr = std::dynamic_pointer_cast<const ShrFactorization>(f)) {
    row["order"] = std::to_string(shr->order());
    row["view_order"] = std::to_string(shr->view_order());
  } else if (auto mf = std::dynamic_pointer_cast<const ModelFitFactorization>(f)) {
    row["model"] = mf->result().spec;
  }
  // Tabulating methods read a measured BRDF at their own grid nodes, i.e. off
  // its interpolant, not at the measured directions: say which one.
  if (m.kind == "svd" || m.kind == "sh-k" || m.kind == "sh-r") {
    if (const std::string how = resampling_note(*b.brdf); !how.empty()) notes.push_back(how);
  }
  row["samples"] = std::to_string(mt.samples);
  const std::pair<const char*, double> metric_cells[] = {
      {"rel_mse", mt.rel_mse},   {"rel_mae", mt.rel_mae}, {"rel_max", mt.rel_max},  {"lin_rmse", mt.lin_rmse},
      {"lin_mae", mt.lin_mae},   {"lin_max", mt.lin_max}, {"cos_rmse", mt.cos_rmse}};
  for (const auto& [k, v] : metric_cells) {
    row[k] = format_number(v);
    if (row[k].empty()) notes.push_back(std::string(k) + " not finite");
  }
  row["storage_floats"] = std::to_string(f->storage_floats());
  row["seconds"] = format_number(std::round(seconds * 1000.0) / 1000.0);
  row["evaluations"] = std::to_string(evaluations);
  row["seed"] = m.kind == "search" || m.kind == "model-fit" ? std::to_string(m.seed) : "";
  row["status"] = "ok";
  if (choice) {
    row["tolerance"] = choice->metric + "<=" + format_number(m.tolerance->value);
    row["tolerance_reached"] = choice->reached ? "true" : "false";
    if (!choice->reached)
      notes.push_back("tolerance not reached up to the cap; best tried: " + format_number(choice->error));
    json tried = json::array();
    for (const auto& t : choice->tried) {
      json tj = {{"value", t.value}, {"view_order", t.view_order},
                 {"error", std::isfinite(t.error) ? json(t.error) : json()}};
      if (t.texture_size) tj["texture_size"] = t.texture_size;
      tried.push_back(tj);
    }
    rec["size_choice"] = {{"knob", choice->knob.empty() ? "terms" : choice->knob}, {"value", choice->value},
                          {"view_order", choice->view_order}, {"metric", choice->metric},
                          {"error", std::isfinite(choice->error) ? json(choice->error) : json()},
                          {"reached", choice->reached}, {"seconds", choice->seconds}, {"tried", tried}};
    if (choice->texture_size) rec["size_choice"]["texture_size"] = choice->texture_size;
  }

  // Files.
  if (plan.experiment.export_factors) {
    if (h) write_factorization(*h, run_dir.string(), "factors");
    else if (auto mf = std::dynamic_pointer_cast<const ModelFitFactorization>(f))
      write_model_fit(mf->result(), (run_dir / "model.json").string());
    else {
      const json d = f->describe();
      write_file_atomic((run_dir / "factorization.json").string(), [&](std::ostream& o) { o << d.dump(2) << "\n"; });
    }
  }
  if (plan.experiment.render) {
    const auto original = renders.get(plan, pr.brdf);
    const SphereRender approx = render_sphere(*f, plan.scene);
    write_comparison_png(*original, approx, (run_dir / "sphere.png").string());
    if (approx.nonfinite) notes.push_back(std::to_string(approx.nonfinite) + " non-finite pixels rendered as 0");
    if (plan.scene.named) row["shade_rmse"] = format_number(shade_rmse(*original, approx));
  }
  // SHRM of an sh-r run under the scene's SH lighting (factor/lighting.h): its
  // storage, time and shade_rmse against the original's render (same scene).
  if (m.shrm && plan.scene.lighting)
    if (auto shr = std::dynamic_pointer_cast<const ShrFactorization>(f)) {
      const auto t1 = Clock::now();
      const Shrm shrm(*shr, *plan.scene.lighting);
      json sj = {{"order", shrm.order()}, {"view_order", shrm.view_order()},
                 {"storage_floats", shrm.storage_floats()}, {"seconds", shrm.seconds()}};
      if (plan.experiment.export_factors)
        write_file_atomic((run_dir / "shrm.json").string(), [&](std::ostream& o) { o << shrm.to_json().dump(1) << "\n"; });
      const auto original = renders.get(plan, pr.brdf);
      const SphereRender sr = render_sphere_radiance(
          [&](const Vec3& n, const Vec3& v) { return shrm.shade(n, v); }, plan.scene.size);
      const double e = shade_rmse(*original, sr);
      sj["shade_rmse"] = std::isfinite(e) ? json(e) : json();
      sj["render_seconds"] = since(t1);
      rec["shrm"] = sj;
      notes.push_back("shrm F_B " + std::to_string(shrm.order()) + ", P_B " + std::to_string(shrm.view_order()) + ": " +
                      std::to_string(shrm.storage_floats()) + " floats, shade_rmse " + format_number(e));
    }
  row["notes"] = join(notes, "; ");
  rec["notes"] = notes;
  rec["wall_seconds"] = since(wall0);
  rec["build"] = build;
  std::vector<std::string> files = list_files(exp_dir, run_dir);
  files.push_back(fs::relative(run_dir / "run.json", exp_dir).generic_string());
  std::sort(files.begin(), files.end());
  rec["row"] = row;
  rec["files"] = files;
  write_file_atomic((run_dir / "run.json").string(), [&](std::ostream& o) { o << rec.dump(2) << "\n"; });
  // The done-marker comes last: a folder without it is an unfinished run.
  write_file_atomic((run_dir / "DONE").string(), [&](std::ostream& o) { o << pr.run_id << "\n"; });
  e.files = files;
  e.record = rec;
  return e;
}

// A finished run's entry, or nothing when the folder is incomplete (no DONE,
// unreadable run.json, a listed file missing).
std::optional<RunEntry> load_done_run(const fs::path& exp_dir, const std::string& run_id) {
  const fs::path run_dir = exp_dir / "runs" / run_id;
  std::error_code ec;
  if (!fs::exists(run_dir / "DONE", ec)) return std::nullopt;
  std::ifstream in(run_dir / "run.json");
  if (!in) return std::nullopt;
  json rec;
  try {
    in >> rec;
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (rec.value("run_id", "") != run_id || !rec.contains("row") || !rec["row"].is_object()) return std::nullopt;
  RunEntry e;
  e.run_id = run_id;
  e.status = "ok";
  for (const auto& [k, v] : rec["row"].items()) e.row[k] = v.is_string() ? v.get<std::string>() : v.dump();
  e.files = rec.value("files", std::vector<std::string>{});
  for (const auto& f : e.files)
    if (!is_path_inside(f) || !fs::exists(exp_dir / f, ec)) return std::nullopt;
  e.record = rec;
  return e;
}

bool incomplete_folder(const fs::path& exp_dir, const std::string& run_id) {
  std::error_code ec;
  return fs::exists(exp_dir / "runs" / run_id, ec);
}

int hardware_cores() { return std::max(1u, std::thread::hardware_concurrency()); }

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

void print_results(std::ostream& out, const OutputFiles& f) {
  out << "results: " << f.results_md << "\n";
  out << "report:  " << f.report << "\n";
}

}  // namespace

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

json build_identity(const json& versions) {
  json b = {{"brdf_factor", versions.value("brdf_factor", "")}};
  if (versions.contains("git_commit")) {
    b["git_commit"] = versions["git_commit"];
    b["git_dirty"] = versions.value("git_dirty", false);
  }
  return b;
}

std::string cached_run_commit(const json& record) {
  const auto it = record.find("build");
  if (it == record.end() || !it->is_object()) return "";
  const auto c = it->find("git_commit");
  return c != it->end() && c->is_string() ? c->get<std::string>() : "";
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
  std::optional<InterruptScope> interrupt_scope;  // SIGINT/SIGTERM stop cleanly (experiments/interrupt.h)
  if (!opt.dry_run) {
    lock.emplace(dir, "run " + opt.config);
    interrupt_scope.emplace();
  }

  // Decide what each run of this shard needs.
  enum class Action { Run, Redo, Cached, Forced, OtherShard };
  std::vector<Action> action(plan.runs.size());
  std::vector<std::optional<RunEntry>> cached(plan.runs.size());
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const PlannedRun& r = plan.runs[i];
    if (static_cast<int>(i % opt.shards) != opt.shard - 1) {
      action[i] = Action::OtherShard;
      continue;
    }
    sum.run_ids.push_back(r.run_id);
    ++sum.in_shard;
    cached[i] = load_done_run(exp_dir, r.run_id);
    if (cached[i]) action[i] = opt.force ? Action::Forced : Action::Cached;
    else action[i] = incomplete_folder(exp_dir, r.run_id) ? Action::Redo : Action::Run;
  }
  size_t n_run = 0, n_cached = 0, n_other = 0;
  for (Action a : action) {
    if (a == Action::Cached) ++n_cached;
    else if (a == Action::OtherShard) ++n_other;
    else ++n_run;
  }

  // The cache key is the config, not the code: say when reused runs come from
  // another build (git commit of the source tree), so results that a fitter
  // change would alter are not mixed in silently.
  const json build = build_identity(software_versions());
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

  if (opt.dry_run) {
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
    return sum;
  }

  {  // Before any work: the folder is writable and has room (experiments/preflight.h).
    std::vector<bool> todo_runs(plan.runs.size());
    for (size_t i = 0; i < plan.runs.size(); ++i)
      todo_runs[i] = action[i] != Action::Cached && action[i] != Action::OtherShard;
    check_output_folder(dir, estimate_output_bytes(plan, todo_runs));
  }
  fs::create_directories(exp_dir / "runs");
  const int jobs_cfg = opt.jobs >= 0 ? opt.jobs : plan.experiment.jobs;
  const int jobs = jobs_cfg > 0 ? jobs_cfg : hardware_cores();
  if (!opt.quiet) {
    err << "experiment " << plan.experiment.name << ": " << sum.in_shard << " runs";
    if (opt.shards > 1) err << " in shard " << opt.shard << "/" << opt.shards << " (of " << plan.runs.size() << ")";
    err << ": " << n_run << " to do, " << n_cached << " cached";
    size_t redo = 0;
    for (Action a : action) redo += a == Action::Redo;
    if (redo) err << " (" << redo << " unfinished, redone)";
    err << "; " << jobs << " job slot" << (jobs > 1 ? "s" : "") << " -> " << dir << "\n";
  }

  // Samples for the runs to do.
  std::map<std::string, std::shared_ptr<const SampleSet>> samples;
  const fs::path cache_dir = exp_dir / "cache" / "samples";
  fs::create_directories(cache_dir);
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    const PlannedRun& r = plan.runs[i];
    if (action[i] == Action::Cached || action[i] == Action::OtherShard || samples.count(r.samples_key)) continue;
    const auto t0 = Clock::now();
    bool hit = false;
    samples[r.samples_key] = make_samples(plan, r, cache_dir, opt.force, &hit);
    if (!opt.quiet)
      err << "samples: " << plan.brdfs[r.brdf].label << " | " << plan.samplings[r.sampling].label << ": "
          << samples[r.samples_key]->summary() << (hit ? " (cached)" : "") << " in " << hms(since(t0)) << "\n";
  }

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
  RenderCache renders;
  std::mutex mu;
  std::condition_variable cv;
  int free_slots = jobs;
  size_t next = 0, done = 0;
  int busy = 0, exited = 0;  // workers inside a run; workers that returned
  const auto start = Clock::now();
  const size_t total = todo.size();
  auto work = [&] {
    for (;;) {
      size_t i;
      int w;
      {
        std::unique_lock<std::mutex> lk(mu);
        if (next >= todo.size() || interrupt_signal()) return;
        // Take the next run in plan order once enough slots are free.
        cv.wait(lk, [&] {
          if (next >= todo.size() || interrupt_signal()) return true;
          const int need = std::min(jobs, plan.methods[plan.runs[todo[next]].method].cores);
          return free_slots >= need;
        });
        if (next >= todo.size() || interrupt_signal()) return;
        ++busy;
        i = todo[next++];
        w = std::min(jobs, plan.methods[plan.runs[i].method].cores);
        free_slots -= w;
        if (!opt.quiet)
          err << "start " << next << "/" << total << " " << plan.runs[i].run_id << " "
              << describe_run(plan, plan.runs[i]) << "\n";
      }
      const PlannedRun& r = plan.runs[i];
      const auto t0 = Clock::now();
      RunEntry e;
      try {
        e = execute_run(plan, r, *samples.at(r.samples_key), exp_dir, renders, build);
      } catch (const std::exception& ex) {
        std::error_code ec;
        fs::remove_all(exp_dir / "runs" / r.run_id, ec);
        e = RunEntry{};
        e.run_id = r.run_id;
        e.status = "failed";
        set_presentation(e.row, plan, r);
        e.row["status"] = "failed";
        const bool oom = dynamic_cast<const std::bad_alloc*>(&ex) != nullptr;  // never "std::bad_alloc" alone
        e.row["notes"] = std::string("failed: ") + (oom ? "out of memory" : ex.what());
        e.record = {{"run_id", r.run_id}, {"error", ex.what()}, {"method", plan.methods[r.method].options}};
      }
      e.shard = opt.shard;
      {
        std::unique_lock<std::mutex> lk(mu);
        entries[i] = std::move(e);
        free_slots += w;
        --busy;
        ++done;
        if (!opt.quiet) {
          const double el = since(start);
          const double eta = done < total ? el / done * (total - done) : 0.0;
          err << "[" << done << "/" << total << "] " << (entries[i].status == "ok" ? "done " : "FAILED ")
              << r.run_id << " in " << std::fixed << std::setprecision(1) << since(t0) << std::defaultfloat
              << " s";
          if (entries[i].status == "ok") err << ", rel_mse " << entries[i].row["rel_mse"];
          else err << ": " << entries[i].row["notes"];
          err << " | elapsed " << hms(el) << ", eta " << hms(eta) << "\n";
        }
      }
      cv.notify_all();
    }
  };
  auto worker = [&] {
    work();
    {
      std::unique_lock<std::mutex> lk(mu);
      ++exited;
    }
    cv.notify_all();
  };
  int stopped_by = 0;    // the signal that stopped the runs, or 0
  bool abandon = false;  // runs still executing when the signal came: exit without waiting for them
  {
    std::vector<std::thread> pool;
    const int n_threads = std::min<int>(jobs, static_cast<int>(todo.size()));
    for (int t = 0; t < n_threads; ++t) pool.emplace_back(worker);
    {
      std::unique_lock<std::mutex> lk(mu);
      while (exited < n_threads && !interrupt_signal()) cv.wait_for(lk, std::chrono::milliseconds(100));
      stopped_by = exited < n_threads || done < total ? interrupt_signal() : 0;
      if (stopped_by) {
        cv.notify_all();  // idle workers see the signal and return
        abandon = busy > 0;
        if (!abandon)
          while (exited < n_threads) cv.wait_for(lk, std::chrono::milliseconds(100));
      }
    }
    if (abandon) {
      for (auto& t : pool) t.detach();  // the process ends below without returning (_Exit)
    } else {
      for (auto& t : pool) t.join();
    }
  }
  std::vector<RunEntry> finished;
  {
    std::unique_lock<std::mutex> lk(mu);
    finished = entries;  // a snapshot: abandoned workers may still write entries
  }
  size_t unfinished = 0;
  if (stopped_by)
    for (size_t i : todo)
      if (finished[i].run_id.empty()) {
        ++unfinished;
        RunEntry& e = finished[i];
        e.run_id = plan.runs[i].run_id;
        e.status = "interrupted";
        e.shard = opt.shard;
        set_presentation(e.row, plan, plan.runs[i]);
        e.row["status"] = "interrupted";
        e.row["notes"] = "interrupted by " + signal_name(stopped_by) + " before it finished; the next run does it";
        e.record = {{"run_id", e.run_id}, {"error", "interrupted"}, {"method", plan.methods[plan.runs[i].method].options}};
      }

  ExperimentOutput o = base_output(plan, dir, opt.shard, opt.shards);
  o.plots = opt.plots && plan.experiment.plots;
  for (size_t i = 0; i < plan.runs.size(); ++i) {
    if (action[i] == Action::OtherShard) continue;
    finished[i].shard = finished[i].shard ? finished[i].shard : opt.shard;
    if (finished[i].status == "ok") {
      if (action[i] == Action::Cached) ++sum.cached;
      else ++sum.executed;
      if (action[i] == Action::Redo) ++sum.redone;
    } else if (finished[i].status != "interrupted") {
      ++sum.failed;
    }
    o.runs.push_back(finished[i]);
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
    if (abandon) {  // runs still executing on detached threads: end the process here
      err << "brdf-factor: " << msg << "\n";
      err.flush();
      std::fflush(nullptr);
      std::_Exit(128 + stopped_by);
    }
    throw Interrupted(msg, stopped_by);
  }
  print_results(out, sum.files);
  if (sum.failed) {
    std::string first;
    for (const auto& r : o.runs)
      if (r.status != "ok") {
        first = r.run_id + ": " + r.row.at("notes");
        break;
      }
    throw std::runtime_error(std::to_string(sum.failed) + " of " + std::to_string(sum.in_shard) +
                             " runs failed (first: " + first + "); they are marked in " + sum.files.results_md +
                             " and will be redone by the next run");
  }
  return sum;
}

RunSummary merge_experiments(const std::vector<std::string>& dirs, const std::string& out_dir, bool quiet,
                             bool plots, std::ostream& out, std::ostream& err) {
  if (dirs.empty()) throw std::invalid_argument("merge: expected at least one shard folder");
  if (out_dir.empty()) throw std::invalid_argument("merge: --out: expected the folder to write");
  std::error_code ec;
  for (const auto& d : dirs)
    if (fs::exists(out_dir, ec) && fs::exists(d, ec) && fs::equivalent(d, out_dir, ec))
      throw std::invalid_argument("merge: --out " + out_dir + " is one of the shard folders; choose a new folder");
  std::vector<ExperimentOutput> shards;
  for (const auto& d : dirs) shards.push_back(read_experiment_manifest(d));
  const ExperimentOutput& first = shards[0];
  std::vector<std::string> problems;
  std::map<int, std::string> shard_dir;
  for (size_t i = 0; i < shards.size(); ++i) {
    const auto& s = shards[i];
    if (s.plan_hash != first.plan_hash)
      problems.push_back(dirs[i] + ": plan " + s.plan_hash + " differs from " + dirs[0] + "'s " + first.plan_hash +
                         " (shards of different configs or overrides)");
    if (s.shards != first.shards)
      problems.push_back(dirs[i] + ": shard count " + std::to_string(s.shards) + " differs from " + dirs[0] +
                         "'s " + std::to_string(first.shards));
    auto [it, fresh] = shard_dir.emplace(s.shard, dirs[i]);
    if (!fresh)
      problems.push_back("shard " + std::to_string(s.shard) + "/" + std::to_string(s.shards) +
                         " given twice: " + it->second + " and " + dirs[i]);
  }
  if (!problems.empty()) throw std::invalid_argument("merge: " + join(problems, "; "));

  // Every planned run exactly once, done.
  std::map<std::string, std::pair<size_t, const RunEntry*>> found;
  std::vector<std::string> duplicates, missing;
  for (size_t i = 0; i < shards.size(); ++i)
    for (const auto& r : shards[i].runs) {
      if (r.status != "ok") continue;
      auto [it, fresh] = found.emplace(r.run_id, std::make_pair(i, &r));
      if (!fresh) duplicates.push_back(r.run_id + " (in " + dirs[it->second.first] + " and " + dirs[i] + ")");
    }
  for (const auto& p : first.plan) {
    const std::string id = p.value("run_id", "");
    auto it = found.find(id);
    if (it == found.end()) {
      const int k = p.value("shard", 1);
      missing.push_back(id + " (shard " + std::to_string(k) + (shard_dir.count(k) ? ", failed or unfinished there" :
                                                               ", no folder given") + ")");
      continue;
    }
    if (!fs::exists(fs::path(dirs[it->second.first]) / "runs" / id / "DONE", ec))
      missing.push_back(id + " (" + dirs[it->second.first] + "/runs/" + id + " has no DONE marker)");
  }
  std::set<std::string> planned;
  for (const auto& p : first.plan) planned.insert(p.value("run_id", ""));
  for (const auto& [id, where] : found)
    if (!planned.count(id)) duplicates.push_back(id + " (in " + dirs[where.first] + " but not in the plan)");
  if (!duplicates.empty() || !missing.empty()) {
    std::string msg = "merge: ";
    if (!missing.empty()) {
      msg += std::to_string(missing.size()) + " of " + std::to_string(first.plan.size()) + " runs missing: ";
      for (size_t i = 0; i < missing.size() && i < 10; ++i) msg += (i ? ", " : "") + missing[i];
      if (missing.size() > 10) msg += ", ...";
    }
    if (!duplicates.empty()) {
      msg += std::string(missing.empty() ? "" : "; ") + std::to_string(duplicates.size()) + " duplicated: ";
      for (size_t i = 0; i < duplicates.size() && i < 10; ++i) msg += (i ? ", " : "") + duplicates[i];
    }
    throw std::invalid_argument(msg);
  }

  // Copy the run folders and write the merged folder.
  const fs::path odir(out_dir);
  const OutdirLock lock(out_dir, "merge");
  fs::create_directories(odir / "runs");
  ExperimentOutput o;
  o.dir = out_dir;
  o.experiment = first.experiment;
  o.config_path = first.config_path;
  o.config_text = first.config_text;
  o.defines = first.defines;
  o.plan_hash = first.plan_hash;
  o.shard = 1;
  o.shards = 1;
  o.plan = first.plan;
  o.plots = plots;
  o.merged_from = dirs;
  RunSummary sum;
  sum.out_dir = out_dir;
  sum.planned = first.plan.size();
  for (const auto& p : first.plan) {
    const std::string id = p.value("run_id", "");
    const auto& [si, entry] = found.at(id);
    const fs::path src = fs::path(dirs[si]) / "runs" / id, dst = odir / "runs" / id;
    if (!(fs::exists(dst, ec) && fs::equivalent(src, dst, ec))) {
      fs::remove_all(dst);
      fs::copy(src, dst, fs::copy_options::recursive);
    }
    o.runs.push_back(*entry);
    sum.run_ids.push_back(id);
  }
  sum.in_shard = o.runs.size();
  sum.cached = o.runs.size();
  if (!quiet) err << "merge: " << o.runs.size() << " runs from " << dirs.size() << " shard folders -> " << out_dir << "\n";
  sum.files = write_experiment_outputs(o, quiet ? nullptr : &err);
  print_results(out, sum.files);
  return sum;
}

}  // namespace bf
