// Every method kind in Python: mccool, fit, search, svd, sh_k, sh_r,
// model_fit and refine. Keyword options carry the config keys' names
// (docs/experiments.md), their types and ranges as the config reader checks
// them, and fill the option structs of factor/ and search/, whose validate()
// applies the configs' rules; each call then does what the
// runner does for one run (experiments/runner.cpp execute_run) with the GIL
// released, and reports metrics on the samples like a results row.
#include <chrono>
#include <cmath>

#include "brdfs/directions.h"
#include "common.h"
#include "factor/homomorphic_fit.h"
#include "factor/isotropy.h"
#include "factor/model_fit.h"
#include "factor/refine.h"
#include "factor/sh_baseline.h"
#include "factor/size_select.h"
#include "factor/svd_baseline.h"
#include "search/rotation4.h"
#include "search/term_search.h"

namespace bf::py_module {

namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

const std::vector<std::string> kMetrics = {"rel_mse", "rel_mae", "rel_max", "lin_rmse", "lin_mae", "lin_max", "cos_rmse"};

// tolerance = {"metric": "rel_mse", "value": 0.01} or ("rel_mse", 0.01), as the config's table.
std::optional<Tolerance> read_tolerance(Options& o) {
  py::object t = o.object("tolerance");
  if (t.is_none()) return std::nullopt;
  Tolerance tol;
  py::object metric, value;
  if (py::isinstance<py::dict>(t)) {
    py::dict d = t;
    for (auto item : d) {
      const std::string k = py::str(item.first);
      if (k != "metric" && k != "value")
        o.fail("tolerance: unknown key '" + k + "' (accepted: metric, value)");
    }
    metric = d.contains("metric") ? py::object(d["metric"]) : py::object(py::str("rel_mse"));
    if (!d.contains("value")) o.fail("tolerance: needs value = <error target > 0>");
    value = d["value"];
  } else if (py::isinstance<py::sequence>(t) && !py::isinstance<py::str>(t) && py::len(t) == 2) {
    metric = t[py::int_(0)];
    value = t[py::int_(1)];
  } else {
    o.fail("tolerance: expected {\"metric\": \"rel_mse\", \"value\": 0.01} or (\"rel_mse\", 0.01), found " +
           std::string(py::repr(t)));
  }
  if (!py::isinstance<py::str>(metric)) o.fail("tolerance: metric: expected a string, found " + std::string(py::repr(metric)));
  tol.metric = metric.cast<std::string>();
  if (std::find(kMetrics.begin(), kMetrics.end(), tol.metric) == kMetrics.end())
    o.fail("tolerance: metric: expected one of rel_mse, rel_mae, rel_max, lin_rmse, lin_mae, lin_max, cos_rmse, found \"" +
           tol.metric + "\"");
  if (py::isinstance<py::bool_>(value) || !(PyFloat_Check(value.ptr()) || PyIndex_Check(value.ptr())))
    o.fail("tolerance: value: expected a number > 0, found " + std::string(py::repr(value)));
  tol.value = py::float_(value).cast<double>();
  validated(o, [&] {
    try {
      tol.validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("tolerance: ") + e.what());
    }
  });
  return tol;
}

void read_fit_options(Options& o, FitOptions& f) {
  f.eps = o.number("eps", f.eps, 0.0, 1.0, true);
  f.smoothing = o.number("smoothing", f.smoothing, 0.0);
  f.subtract_eps = o.boolean("subtract_eps", f.subtract_eps);
  f.solve_last = o.integer("solve_last", f.solve_last, 1, 64);
  const std::string solver = o.choice("solver", "auto", {"auto", "dense", "sparse", "qr"});
  f.solver = solver == "dense"    ? FitOptions::Solver::Dense
             : solver == "sparse" ? FitOptions::Solver::Sparse
             : solver == "qr"     ? FitOptions::Solver::ReferenceQR
                                  : FitOptions::Solver::Auto;
}

Parameterization read_param(Options& o, Parameterization def) {
  return parse_parameterization(o.choice("parameterization", to_string(def), {"wiwo", "halfdiff"}));
}

// texture_size: an integer, or "auto" with a tolerance: the ladder (texture_ladder,
// default 8, 12, 16, 24, 32) is tried. Returns the fixed size (or the ladder's
// largest entry) and fills ladder for "auto".
int read_texture_size(Options& o, int def, int hi, std::vector<int>& ladder) {
  py::object t = o.object("texture_size");
  py::object l = o.object("texture_ladder");
  if (py::isinstance<py::str>(t) && t.cast<std::string>() == "auto") {
    if (l.is_none()) ladder = default_texture_ladder();
    else {
      if (!py::isinstance<py::sequence>(l)) o.fail("texture_ladder: expected a list of integers, found " + std::string(py::repr(l)));
      for (auto e : l) {
        if (py::isinstance<py::bool_>(e) || !PyIndex_Check(e.ptr()))
          o.fail("texture_ladder: expected a list of integers, found an element " + std::string(py::repr(e)));
        ladder.push_back(e.cast<int>());
      }
    }
    validated(o, [&] { validate_texture_ladder(ladder, 2, hi, "texture_ladder"); });
    return ladder.back();
  }
  if (!l.is_none()) o.fail("texture_ladder: applies only with texture_size = \"auto\"");
  if (t.is_none()) return def;
  if (py::isinstance<py::bool_>(t) || !PyIndex_Check(t.ptr()))
    o.fail("texture_size: expected an integer in 2.." + std::to_string(hi) + " or \"auto\", found " + std::string(py::repr(t)));
  const long long v = py::int_(t).cast<long long>();
  if (v < 2 || v > hi)
    o.fail("texture_size: expected an integer in 2.." + std::to_string(hi) + " or \"auto\", found " + std::to_string(v));
  return static_cast<int>(v);
}

// The refinement stage of the homomorphic kinds (refine = "none" | "linear" |
// "cosine" | "blend", refine_blend, refine_iterations, refine_smoothing).
struct RefineStage {
  std::string refine = "none";
  RefineOptions ro;
};
RefineStage read_refine(Options& o) {
  RefineStage s;
  s.refine = o.choice("refine", "none", {"none", "linear", "cosine", "blend"});
  if (s.refine != "none") s.ro.objective = s.refine;
  s.ro.blend_weight = o.number("refine_blend", s.ro.blend_weight, 0.0);
  s.ro.max_iterations = o.integer("refine_iterations", s.ro.max_iterations, 1, 100000);
  s.ro.smoothing = o.has("refine_smoothing") ? o.number("refine_smoothing", 0.0, 0.0) : -1.0;  // -1: the fit's smoothing
  s.ro.threads = 1;  // as the runner
  return s;
}
void validate_refine(const Options& o, RefineStage& s, const FitOptions& fit) {
  if (s.ro.smoothing < 0) s.ro.smoothing = fit.smoothing;
  // Checked even with refine = "none", as the config does (a sweep over refine may carry them).
  validated(o, [&] {
    try {
      s.ro.validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("refinement: ") + e.what());
    }
  });
}

double read_metric_eps(Options& o) {
  return o.number("metric_eps", 1e-5, 0.0, 1.0, true);
}

json refine_record(const RefineReport& rep, const RefineOptions& ro) {
  return {{"objective", rep.objective},   {"linear_solver", rep.linear_solver}, {"iterations", rep.iterations},
          {"seconds", rep.seconds},       {"initial_cost", rep.initial_cost},   {"final_cost", rep.final_cost},
          {"termination", rep.termination}, {"parameters", rep.parameters},     {"residuals", rep.residuals},
          {"texels_added", rep.texels_added}, {"blend_weight", ro.blend_weight}, {"smoothing", ro.smoothing}};
}

json choice_record(const SizeChoice& c) {
  json tried = json::array();
  for (const auto& t : c.tried) tried.push_back({{"value", t.value}, {"view_order", t.view_order}, {"error", t.error}});
  return {{"knob", c.knob},   {"value", c.value},     {"view_order", c.view_order}, {"texture_size", c.texture_size},
          {"metric", c.metric}, {"error", c.error},   {"reached", c.reached},       {"tried", tried}};
}

// What every homomorphic kind does after its fit: optional refinement
// (a failed one keeps the fit, as the runner does), metrics, the record.
struct HomomorphicRun {
  std::shared_ptr<const HomomorphicFactorization> h;
  std::vector<double> errs;
  int evaluations = 0;
  json info = json::object();
};
std::shared_ptr<PyFactorization> finish_homomorphic(HomomorphicRun r, const SampleSet& s, const RefineStage& st,
                                                    double metric_eps, Clock::time_point t0) {
  const LogTransform lt = LogTransform::of(s, metric_eps);
  if (st.refine != "none") {
    const Metrics before = evaluate_metrics(*r.h, s, lt);
    r.info["metrics_before_refine"] = {{"rel_mse", before.rel_mse}, {"lin_rmse", before.lin_rmse}, {"cos_rmse", before.cos_rmse}};
    RefineReport rep;
    try {
      r.h = refine(*r.h, s, st.ro, &rep);
      r.info["refinement"] = refine_record(rep, st.ro);
    } catch (const std::runtime_error& ex) {
      r.info["refinement"] = {{"failed", ex.what()}};
    }
  }
  auto p = wrap(r.h);
  p->seconds = since(t0);
  p->metrics = evaluate_metrics(*r.h, s, lt);
  p->metric_eps = metric_eps;
  p->errors_after_term = std::move(r.errs);
  p->evaluations = r.evaluations;
  p->info = std::move(r.info);
  return p;
}

std::shared_ptr<PyFactorization> finish_tabulated(FactorizationPtr f, const std::shared_ptr<SampleSet>& s,
                                                  double metric_eps, Clock::time_point t0, json info) {
  auto p = wrap(f);
  p->seconds = since(t0);
  p->metric_eps = metric_eps;
  if (s) p->metrics = evaluate_metrics(*f, *s, LogTransform::of(*s, metric_eps));
  if (auto svd = std::dynamic_pointer_cast<const SvdFactorization>(f); svd && s) {
    const LogTransform lt = LogTransform::of(*s, metric_eps);
    for (int k = 1; k <= svd->rank(); ++k) p->errors_after_term.push_back(evaluate_metrics(*svd->truncated(k), *s, lt).rel_mse);
  }
  p->info = std::move(info);
  return p;
}

// projections for kind "fit": each a name ("wi", "wo", "h", "d"), a 2x4 matrix
// (parameterization from the call), or a dict {name | matrix, parameterization, reciprocal}.
std::vector<TermSpec> read_projections(Options& o, Parameterization param, bool reciprocity, int res) {
  py::object list = o.object("projections");
  if (list.is_none() || !py::isinstance<py::sequence>(list) || py::isinstance<py::str>(list) || py::len(list) == 0)
    o.fail("projections: expected a non-empty list of names (\"wi\", \"wo\", \"h\", \"d\"), 2x4 matrices or dicts "
           "{name | matrix, parameterization, reciprocal}");
  std::vector<TermSpec> out;
  size_t j = 0;
  for (auto e : list) {
    const std::string field = "projections[" + std::to_string(j++) + "]";
    Parameterization p = param;
    bool recip = reciprocity;
    py::object name, matrix;
    if (py::isinstance<py::str>(e)) name = py::reinterpret_borrow<py::object>(e);
    else if (py::isinstance<py::dict>(e)) {
      py::dict d = py::reinterpret_borrow<py::dict>(e);
      for (auto item : d) {
        const std::string k = py::str(item.first);
        if (k != "name" && k != "matrix" && k != "parameterization" && k != "reciprocal")
          o.fail(field + ": unknown key '" + k + "' (accepted: matrix, name, parameterization, reciprocal)");
      }
      if (d.contains("name")) name = d["name"];
      if (d.contains("matrix")) matrix = d["matrix"];
      if (d.contains("parameterization")) {
        const std::string ps = py::str(d["parameterization"]);
        if (ps != "wiwo" && ps != "halfdiff") o.fail(field + ".parameterization: expected \"wiwo\" or \"halfdiff\", found \"" + ps + "\"");
        p = parse_parameterization(ps);
      }
      if (d.contains("reciprocal")) {
        if (!py::isinstance<py::bool_>(d["reciprocal"])) o.fail(field + ".reciprocal: expected True or False");
        recip = d["reciprocal"].cast<bool>();
      }
      if (name && matrix) o.fail(field + ".name: matrix and name are alternatives: give one of them, found both");
      if (!name && !matrix) o.fail(field + ": expected matrix = [[4 numbers], [4 numbers]] or name = \"wi\" | \"wo\" | \"h\" | \"d\"");
    } else
      matrix = py::reinterpret_borrow<py::object>(e);
    Mat24 P = Mat24::Zero();
    if (name) {
      const std::string n = py::str(name);
      if (n != "wi" && n != "wo" && n != "h" && n != "d")
        o.fail(field + ".name: expected one of \"wi\", \"wo\", \"h\", \"d\", found \"" + n + "\"");
      p = (n == "wi" || n == "wo") ? Parameterization::WiWo : Parameterization::HalfDiff;
      P = (n == "wi" || n == "h") ? projection_first_pair(p, res).P : projection_second_pair(p, res).P;
    } else {
      auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(matrix);
      if (!a || a.ndim() != 2 || a.shape(0) != 2 || a.shape(1) != 4) {
        PyErr_Clear();
        o.fail(field + ".matrix: expected [[4 numbers], [4 numbers]] (a 2x4 matrix), found " + std::string(py::repr(matrix)));
      }
      for (int r = 0; r < 2; ++r)
        for (int c = 0; c < 4; ++c) {
          P(r, c) = a.at(r, c);
          if (!std::isfinite(P(r, c))) o.fail(field + ".matrix: expected finite numbers");
        }
    }
    Projection proj{p, P, res};
    try {
      proj.validate();
    } catch (const std::invalid_argument& ex) {
      o.fail(field + (name ? ".name: " : ".matrix: ") + ex.what() + " (rows must be orthonormal)");
    }
    out.push_back({proj, recip, std::nullopt});
  }
  return out;
}

// ------------------------------------------------------------------ kinds

std::shared_ptr<PyFactorization> run_mccool(const SampleSet& s, const py::kwargs& kw) {
  Options o("mccool", kw);
  std::vector<int> ladder;
  const int res = read_texture_size(o, 16, 1024, ladder);
  const std::optional<Tolerance> tol = read_tolerance(o);
  if (tol && ladder.empty())
    o.fail("tolerance: kind = \"mccool\" has exactly 2 textures: a tolerance can only choose the resolution "
           "(set texture_size = \"auto\")");
  if (!tol && !ladder.empty()) o.fail("texture_size: texture_size = \"auto\" needs a tolerance (the error target that picks the size)");
  FitOptions fit;
  read_fit_options(o, fit);
  RefineStage st = read_refine(o);
  const double metric_eps = read_metric_eps(o);
  o.finish();
  validated(o, [&] { fit.validate(); });
  validate_refine(o, st, fit);
  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  const FitData data(s, fit.eps);
  HomomorphicRun r;
  if (tol) {
    const SizeChoice c = select_homomorphic_size(data, s, LogTransform::of(s, metric_eps), mccool_terms, 2, 2, fit,
                                                 "mccool", *tol, ladder);
    r.h = std::dynamic_pointer_cast<const HomomorphicFactorization>(c.result);
    r.errs = c.errors_after_term;
    r.info["size_choice"] = choice_record(c);
  } else {
    r.h = fit_homomorphic(data, mccool_terms(res), fit, "mccool", &r.errs);
  }
  return finish_homomorphic(std::move(r), s, st, metric_eps, t0);
}

std::shared_ptr<PyFactorization> run_fit(const SampleSet& s, const py::kwargs& kw) {
  Options o("fit", kw);
  std::vector<int> ladder;
  const int res = read_texture_size(o, 16, 1024, ladder);
  const Parameterization param = read_param(o, Parameterization::WiWo);
  const bool reciprocity = o.boolean("reciprocity", false);
  FitOptions fit;
  read_fit_options(o, fit);
  const std::optional<Tolerance> tol = read_tolerance(o);
  if (!tol && !ladder.empty()) o.fail("texture_size: texture_size = \"auto\" needs a tolerance (the error target that picks the size)");
  const std::vector<TermSpec> projections = read_projections(o, param, reciprocity, res);
  const int n = static_cast<int>(projections.size());
  const bool has_terms = o.has("terms");
  const int terms = o.integer("terms", n, 1, 1024);
  if (terms > n)
    o.fail("terms: terms = " + std::to_string(terms) + " but only " + std::to_string(n) +
           " projections are given (terms uses the first `terms` of them)");
  const int cap = has_terms ? terms : n;
  RefineStage st = read_refine(o);
  const double metric_eps = read_metric_eps(o);
  o.finish();
  validated(o, [&] { fit.validate(); });
  validate_refine(o, st, fit);
  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  const FitData data(s, fit.eps);
  HomomorphicRun r;
  if (tol) {
    const auto terms_at = [&](int size) { return terms_at_resolution(projections, size); };
    const SizeChoice c = select_homomorphic_size(data, s, LogTransform::of(s, metric_eps), terms_at, 1, cap, fit, "fit",
                                                 *tol, ladder.empty() ? std::vector<int>{res} : ladder);
    r.h = std::dynamic_pointer_cast<const HomomorphicFactorization>(c.result);
    r.errs = c.errors_after_term;
    r.info["size_choice"] = choice_record(c);
  } else {
    r.h = fit_homomorphic(data, std::vector<TermSpec>(projections.begin(), projections.begin() + terms), fit, "fit", &r.errs);
  }
  return finish_homomorphic(std::move(r), s, st, metric_eps, t0);
}

std::shared_ptr<PyFactorization> run_search(const SampleSet& s, const py::kwargs& kw) {
  Options o("search", kw);
  SearchOptions so;
  // As in configs: Cole's greedy search unless strategy = "structured".
  so.strategy = o.choice("strategy", "greedy", {"greedy", "structured"});
  so.term_param = o.choice("term_param", so.term_param, {"either", "fixed"});
  so.keep = o.integer("keep", so.keep, 1, 1000);
  so.polish_sweeps = o.integer("polish_sweeps", so.polish_sweeps, 0, 1000);
  so.beam_width = o.integer("beam_width", so.beam_width, 1, 1000);
  so.final_joint = o.boolean("final_joint", so.final_joint);
  so.joint_polish_terms = o.integer("joint_polish_terms", so.joint_polish_terms, 0, 64);
  so.param = read_param(o, so.param);
  const std::optional<Tolerance> tol = read_tolerance(o);
  so.terms = o.integer("terms", tol ? 8 : so.terms, 1, 64);
  so.texture_size = o.integer("texture_size", so.texture_size, 2, 1024);
  so.search_texture_size = o.integer("search_texture_size", 0, 0, 1024);
  if (so.search_texture_size == 1) o.fail("search_texture_size: expected 0 (same as texture_size) or 2..1024, found 1");
  so.restarts = o.integer("restarts", so.restarts, 0, 100000);
  so.guesses = o.texts("guesses");
  so.reciprocity = o.boolean("reciprocity", false);
  so.optimizer = o.choice("optimizer", so.optimizer, {"powell", "praxis", "bobyqa", "neldermead", "sbplx", "direct", "crs"});
  so.powell.ftol = o.number("ftol", so.powell.ftol, 0.0, 1.0, true);
  so.powell.line_tol = o.number("line_tol", so.powell.line_tol, 0.0, 10.0, true);
  so.powell.initial_step = o.number("initial_step", so.powell.initial_step, 0.0, 10.0, true);
  so.powell.max_sweeps = o.integer("max_sweeps", so.powell.max_sweeps, 1, 100000);
  so.powell.max_evaluations = o.integer("max_evaluations", so.powell.max_evaluations, 10, 100000000);
  so.threads = o.integer("threads", 0, 0, 1024);
  so.beam = o.integer("beam", so.beam, 1, 100000);
  so.backfit_sweeps = o.integer("backfit_sweeps", so.backfit_sweeps, 0, 1000);
  so.backfit_restarts = o.integer("backfit_restarts", so.backfit_restarts, 0, 100000);
  so.seed = o.seed("seed", 1);
  read_fit_options(o, so.fit);
  RefineStage st = read_refine(o);
  const double metric_eps = read_metric_eps(o);
  o.finish();
  if (tol && so.beam != 1)
    o.fail("tolerance: a tolerance stops the greedy search after a term, which needs beam = 1; found beam = " +
           std::to_string(so.beam));
  validated(o, [&] { so.validate(); });
  validate_refine(o, st, so.fit);

  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  const FitData data(s, so.fit.eps);
  const LogTransform lt = LogTransform::of(s, metric_eps);
  SizeChoice c;
  if (so.beam == 1) {
    // Greedy search: after each term, Ctrl-C is noticed (KeyboardInterrupt) and
    // a tolerance may end the search (the runner's stopping rule).
    so.stop_after_term = [&](const HomomorphicFactorization& hf) {
      check_signals();
      if (!tol) return false;
      const double v = metric_value(evaluate_metrics(hf, s, lt), tol->metric);
      c.tried.push_back({static_cast<int>(hf.terms().size()), -1, v});
      c.value = static_cast<int>(hf.terms().size());
      c.error = v;
      c.reached = v <= tol->value;
      return c.reached;
    };
  }
  const SearchResult sr = search_factorization(data, so);
  HomomorphicRun r;
  r.h = sr.factorization;
  r.errs = sr.rel_mse_after_term;
  r.evaluations = sr.evaluations;
  json terms = json::array();
  for (const auto& t : sr.terms)
    terms.push_back({{"rotation", t.rotation},
                     {"search_rel_mse", std::isfinite(t.search_rel_mse) ? json(t.search_rel_mse) : json()},
                     {"evaluations", t.evaluations},
                     {"seconds", t.seconds},
                     {"best_start", t.best_start},
                     {"backfit_evaluations", t.backfit_evaluations},
                     {"backfit_moves", t.backfit_moves}});
  r.info["terms"] = terms;
  r.info["search_rel_mse"] = sr.search_rel_mse;
  if (sr.beam_rel_mse.size() > 1) {
    r.info["beam_rel_mse"] = sr.beam_rel_mse;
    r.info["best_branch"] = sr.best_branch;
  }
  if (tol) {
    c.method = "search";
    c.knob = "terms";
    c.metric = tol->metric;
    r.info["size_choice"] = choice_record(c);
  }
  return finish_homomorphic(std::move(r), s, st, metric_eps, t0);
}

std::shared_ptr<SampleSet> optional_samples(const py::object& samples) {
  if (samples.is_none()) return nullptr;
  return samples.cast<std::shared_ptr<SampleSet>>();
}

std::shared_ptr<PyFactorization> run_svd(const PyBrdf& b, const py::object& samples_in, const py::kwargs& kw) {
  auto samples = optional_samples(samples_in);
  Options o("svd", kw);
  SvdOptions v;
  std::vector<int> ladder;
  v.res = read_texture_size(o, v.res, 256, ladder);
  const std::optional<Tolerance> tol = read_tolerance(o);
  if (!tol && !ladder.empty()) o.fail("texture_size: texture_size = \"auto\" needs a tolerance (the error target that picks the size)");
  v.rank = o.integer("terms", tol ? 16 : v.rank, 1, 100000);
  v.param = read_param(o, v.param);
  v.log = o.boolean("log", v.log);
  if (!v.log)
    for (const char* k : {"eps", "subtract_eps"})
      if (o.has(k)) o.fail(std::string(k) + ": applies only to the log-space SVD: set log = True or remove " + k);
  v.eps = o.number("eps", v.eps, 0.0, 1.0, true);
  v.subtract_eps = o.boolean("subtract_eps", v.subtract_eps);
  v.rim_inset = o.number("rim_inset", v.rim_inset, 0.0, 0.5);
  v.extend_below_horizon = o.boolean("extend_below_horizon", v.extend_below_horizon);
  v.float_textures = o.boolean("float_textures", v.float_textures);
  const double metric_eps = read_metric_eps(o);
  o.finish();
  validated(o, [&] { v.validate(); });
  if (tol && !samples) o.fail("tolerance: needs samples (the error is measured on them)");
  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  FactorizationPtr f;
  json info = json::object();
  if (tol) {
    const SizeChoice c = ladder.empty() ? select_svd_rank(*b.brdf, *samples, v, *tol, v.rank)
                                        : select_svd_size(*b.brdf, *samples, v, *tol, v.rank, ladder);
    f = c.result;
    info["size_choice"] = choice_record(c);
  } else {
    f = fit_svd(*b.brdf, v);
  }
  return finish_tabulated(f, samples, metric_eps, t0, info);
}

std::shared_ptr<PyFactorization> run_shk(const PyBrdf& b, const py::object& samples_in, const py::kwargs& kw) {
  auto samples = optional_samples(samples_in);
  Options o("sh-k", kw);
  ShkOptions k;
  const std::optional<Tolerance> tol = read_tolerance(o);
  k.order = o.integer("order", tol ? 30 : k.order, 0, 200);
  k.view_res = o.integer("texture_size", k.view_res, 2, 512);
  k.theta_nodes = o.integer("theta_nodes", 0, 0, 100000);
  k.phi_nodes = o.integer("phi_nodes", 0, 0, 100000);
  k.rim_inset = o.number("rim_inset", k.rim_inset, 0.0, 0.1, true);
  k.min_cos = o.number("min_cos", k.min_cos, 0.0, 1.0, true);
  k.float_textures = o.boolean("float_textures", k.float_textures);
  const bool reduce = o.boolean("reduce_isotropic", true);
  const double metric_eps = read_metric_eps(o);
  o.finish();
  validated(o, [&] { k.validate(); });
  if (tol && !samples) o.fail("tolerance: needs samples (the error is measured on them)");
  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  // An isotropic BRDF (by the azimuthal-invariance test) is stored along phi_v = 0 only, as in the runner.
  const IsotropyResult iso = test_isotropy(*b.brdf);
  k.reduced = reduce && iso.isotropic;
  json info = {{"reduced", k.reduced}, {"isotropic", iso.isotropic}};
  FactorizationPtr f;
  if (tol) {
    const SizeChoice c = select_shk_order(*b.brdf, *samples, k, *tol, k.order);
    f = c.result;
    info["size_choice"] = choice_record(c);
  } else {
    f = fit_shk(*b.brdf, k);
  }
  return finish_tabulated(f, samples, metric_eps, t0, info);
}

std::shared_ptr<PyFactorization> run_shr(const PyBrdf& b, const py::object& samples_in, const py::kwargs& kw) {
  auto samples = optional_samples(samples_in);
  Options o("sh-r", kw);
  ShrOptions s;
  const std::optional<Tolerance> tol = read_tolerance(o);
  const bool has_order = o.has("order"), has_view = o.has("view_order");
  s.max_order = o.integer("max_order", s.max_order, 0, 400);
  s.max_view_order = o.integer("max_view_order", s.max_view_order, 0, 100);
  s.order = o.integer("order", -1, 0, 400);
  s.view_order = o.integer("view_order", -1, 0, 100);
  if (has_order != has_view)
    o.fail(std::string(has_order ? "order" : "view_order") +
           ": fixed orders need both order and view_order (or neither: orders chosen by energy_eps or tolerance)");
  if ((has_order || has_view) && tol)
    o.fail("tolerance: tolerance chooses the orders: remove order/view_order (the caps are max_order, max_view_order)");
  if (o.has("energy_eps") && (has_order || tol))
    o.fail("energy_eps: energy_eps chooses the orders; it contradicts fixed orders or a tolerance");
  s.energy_eps = o.number("energy_eps", s.energy_eps, 0.0, 1.0, true);
  s.theta_i_nodes = o.integer("theta_i_nodes", 0, 0, 100000);
  s.theta_o_nodes = o.integer("theta_o_nodes", 0, 0, 100000);
  s.phi_nodes = o.integer("phi_nodes", 0, 0, 100000);
  s.min_cos = o.number("min_cos", s.min_cos, 0.0, 1.0, true);
  const double metric_eps = read_metric_eps(o);
  o.finish();
  validated(o, [&] { s.validate(); });
  if (tol && !samples) o.fail("tolerance: needs samples (the error is measured on them)");
  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  FactorizationPtr f;
  json info = json::object();
  if (tol) {
    const SizeChoice c = select_shr_orders_by_metric(*b.brdf, *samples, s, *tol);
    f = c.result;
    info["size_choice"] = choice_record(c);
  } else {
    f = fit_shr(*b.brdf, s);
  }
  return finish_tabulated(f, samples, metric_eps, t0, info);
}

std::shared_ptr<PyFactorization> run_model_fit(const SampleSet& s, const py::kwargs& kw) {
  Options o("model-fit", kw);
  ModelFitOptions f;
  f.model = o.text("model", f.model);
  f.metric = o.choice("metric", f.metric, {"cosine", "log"});
  f.cube_root = o.boolean("cube_root", f.cube_root);
  if (f.cube_root && f.metric != "cosine")
    o.fail("cube_root: cube_root = True applies to metric = \"cosine\" only, found metric = \"" + f.metric + "\"");
  f.anisotropic = o.boolean("anisotropic", f.anisotropic);
  f.lobes = o.integer("lobes", f.lobes, 1, 3);
  f.eps = o.number("eps", f.eps, 0.0, 1.0, true);
  f.starts = o.integer("starts", f.starts, 1, 1000);
  f.seed = o.seed("seed", 1);
  f.max_iterations = o.integer("max_iterations", f.max_iterations, 1, 100000);
  f.threads = o.integer("threads", 0, 0, 1024);
  const double metric_eps = read_metric_eps(o);
  o.finish();
  validated(o, [&] { check_model_fit(f); });
  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  auto mf = std::make_shared<ModelFitFactorization>(fit_model(s, f));
  const ModelFitResult& res = mf->result();
  json params = json::object();
  for (const auto& [k, v] : res.parameters) params[k] = v;
  json info = {{"spec", res.spec},         {"parameters", params},          {"cost", res.cost},
               {"best_start", res.best_start}, {"start_costs", res.start_costs}, {"iterations", res.iterations}};
  auto p = wrap(mf);
  p->seconds = since(t0);
  p->metric_eps = metric_eps;
  p->metrics = evaluate_metrics(*mf, s, LogTransform::of(s, metric_eps));
  p->evaluations = res.iterations;
  p->info = std::move(info);
  return p;
}

std::shared_ptr<PyFactorization> run_refine(const PyFactorization& start, const SampleSet& s, const py::kwargs& kw) {
  auto h = std::dynamic_pointer_cast<const HomomorphicFactorization>(start.f);
  if (!h)
    throw std::invalid_argument("refine: expected a factorization of mccool, fit or search, found method " + start.f->method());
  Options o("refine", kw);
  RefineOptions ro;
  ro.objective = o.choice("objective", ro.objective, {"linear", "cosine", "blend"});
  ro.blend_weight = o.number("blend_weight", ro.blend_weight);
  ro.max_iterations = o.integer("max_iterations", ro.max_iterations);
  ro.smoothing = o.number("smoothing", ro.smoothing);
  ro.threads = o.integer("threads", ro.threads);
  ro.function_tolerance = o.number("function_tolerance", ro.function_tolerance);
  const std::string ls = o.choice("linear_solver", "auto", {"auto", "suitesparse", "eigen_sparse", "cgnr"});
  ro.linear_solver = ls == "suitesparse"    ? RefineOptions::LinearSolver::SuiteSparse
                     : ls == "eigen_sparse" ? RefineOptions::LinearSolver::EigenSparse
                     : ls == "cgnr"         ? RefineOptions::LinearSolver::CGNR
                                            : RefineOptions::LinearSolver::Auto;
  const double metric_eps = read_metric_eps(o);
  o.finish();
  validated(o, [&] { ro.validate(); });
  py::gil_scoped_release release;
  const auto t0 = Clock::now();
  RefineReport rep;
  auto out = refine(*h, s, ro, &rep);
  auto p = wrap(out);
  p->seconds = since(t0);
  p->metric_eps = metric_eps;
  p->metrics = evaluate_metrics(*out, s, LogTransform::of(s, metric_eps));
  p->evaluations = rep.iterations;
  p->info = {{"refinement", refine_record(rep, ro)}};
  return p;
}

}  // namespace

void bind_methods(py::module_& m) {
  m.def("mccool", &run_mccool, py::arg("samples"),
        R"doc(mccool(samples, **options) -> Factorization

McCool's fixed projections (p(wi) p(h) p(wo), two textures). Options as the
config's kind = "mccool": texture_size (or "auto" with tolerance and
texture_ladder), eps, smoothing, subtract_eps, solve_last, solver,
refine ("none" | "linear" | "cosine" | "blend"), refine_blend,
refine_iterations, refine_smoothing; metric_eps (the experiment's).)doc");
  m.def("fit", &run_fit, py::arg("samples"),
        R"doc(fit(samples, projections=[...], **options) -> Factorization

Homomorphic fit of given projections: each a name ("wi", "wo", "h", "d"), a
2x4 matrix (rows orthonormal) or a dict {name | matrix, parameterization,
reciprocal}. Options as kind = "fit": terms, texture_size, parameterization,
reciprocity, tolerance, the fit options and refinement of mccool().)doc");
  m.def("search", &run_search, py::arg("samples"),
        R"doc(search(samples, **options) -> Factorization

Cole's automatic factorization (Powell search over 4D rotations); with
strategy="structured" the search of docs/search.md. Options as kind =
"search": strategy, term_param, keep, polish_sweeps, beam_width, final_joint,
joint_polish_terms, terms, parameterization, texture_size, search_texture_size,
restarts, guesses, reciprocity, optimizer, ftol, line_tol, initial_step,
max_sweeps, max_evaluations, threads, seed, beam, backfit_sweeps,
backfit_restarts, tolerance, the fit options and refinement of mccool().
Greedy searches (beam = 1) notice Ctrl-C after each term.)doc");
  m.def("svd", &run_svd, py::arg("brdf"), py::arg("samples") = py::none(),
        R"doc(svd(brdf, samples=None, **options) -> Factorization

Kautz-McCool SVD of the tabulated BRDF. Options as kind = "svd":
texture_size, terms, parameterization, log, eps, subtract_eps, rim_inset,
extend_below_horizon, float_textures, tolerance (needs samples). Metrics are
reported when samples are given.)doc");
  m.def("sh_k", &run_shk, py::arg("brdf"), py::arg("samples") = py::none(),
        R"doc(sh_k(brdf, samples=None, **options) -> Factorization

Kautz-Sloan-Snyder SH projection. Options as kind = "sh-k": order,
texture_size, theta_nodes, phi_nodes, rim_inset, min_cos, float_textures,
reduce_isotropic, tolerance (needs samples).)doc");
  m.def("sh_r", &run_shr, py::arg("brdf"), py::arg("samples") = py::none(),
        R"doc(sh_r(brdf, samples=None, **options) -> Factorization

Ramamoorthi-Hanrahan reflection-space SH (isotropic BRDFs). Options as
kind = "sh-r": order, view_order, max_order, max_view_order, energy_eps,
theta_i_nodes, theta_o_nodes, phi_nodes, min_cos, tolerance (needs samples).)doc");
  m.def("model_fit", &run_model_fit, py::arg("samples"),
        R"doc(model_fit(samples, **options) -> Factorization

Ceres fit of an analytic model. Options as kind = "model-fit": model,
metric, cube_root, anisotropic, lobes, eps, starts, seed, max_iterations,
threads.)doc");
  m.def("refine", &run_refine, py::arg("factorization"), py::arg("samples"),
        R"doc(refine(factorization, samples, **options) -> Factorization

Ceres refinement of a mccool/fit/search factorization in linear space
(factor/refine.h): objective ("linear" | "cosine" | "blend"), blend_weight,
max_iterations, smoothing, threads, function_tolerance, linear_solver
("auto" | "suitesparse" | "eigen_sparse" | "cgnr").)doc");
}

}  // namespace bf::py_module
