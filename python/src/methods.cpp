// Every method kind in Python: one function per registered kind (the
// catalogue's method_call_specs: name, input, docstring from the key docs),
// and refine. A call's keyword options become the [[method]] table
// a config would hold and are read by the config reader's code for that table
// (experiments/plan/config_reader.h read_method_table, the kinds of
// experiments/methods/): keys, defaults, ranges, rules and error messages live
// there once. The call then runs the kind as the runner runs one run
// (experiments/run/runner.cpp execute_run: MethodKind::run), in a LongCall (GIL
// released, Ctrl-C cancels), and reports metrics on the samples like a
// results row.
#include <algorithm>
#include <chrono>
#include <sstream>
#include <toml++/toml.h>

#include "common.h"
#include "experiments/common/cli_util.h"
#include "experiments/config/config.h"
#include "experiments/methods/method_kind.h"
#include "factor/isotropy.h"
#include "factor/refine.h"

namespace bf::py_module {

namespace {

using json = nlohmann::json;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string shown(const py::handle& o) {
  std::string r = py::repr(o);
  if (r.size() > 60) r = r.substr(0, 57) + "...";
  return r + " (" + std::string(py::str(py::type::of(o).attr("__name__"))) + ")";
}

// Puts x into table t under key, or appends it to array a.
template <class T>
void emit(T&& x, toml::table* t, const std::string& key, toml::array* a) {
  if (t) t->insert_or_assign(key, std::forward<T>(x));
  else a->push_back(std::forward<T>(x));
}

// The TOML value of a Python value (bool, int, float, str; dict as a table;
// list, tuple or numpy array as an array), put as emit() does; false for
// anything else.
bool to_toml(const py::handle& v, toml::table* t, const std::string& key, toml::array* a) {
  if (py::isinstance<py::bool_>(v) || py::isinstance(v, py::module_::import("numpy").attr("bool_"))) {
    emit(v.cast<bool>(), t, key, a);
  } else if (py::isinstance<py::str>(v)) {
    emit(v.cast<std::string>(), t, key, a);
  } else if (py::isinstance<py::array>(v)) {  // before the number tests: arrays have __index__ and __float__
    return to_toml(v.attr("tolist")(), t, key, a);
  } else if (PyIndex_Check(v.ptr())) {
    const py::int_ i = py::reinterpret_steal<py::int_>(PyNumber_Index(v.ptr()));
    if (i >= py::int_(INT64_MIN) && i <= py::int_(INT64_MAX)) emit(i.cast<int64_t>(), t, key, a);
    else emit(py::float_(i).cast<double>(), t, key, a);  // out of TOML's range: shown as the number it is
  } else if (PyFloat_Check(v.ptr()) || (py::hasattr(v, "__float__") && !py::isinstance<py::sequence>(v))) {
    emit(py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>(), t, key, a);
  } else if (py::isinstance<py::dict>(v)) {
    toml::table sub;
    for (auto item : py::reinterpret_borrow<py::dict>(v)) {
      if (!py::isinstance<py::str>(item.first)) return false;
      if (item.second.is_none()) continue;
      if (!to_toml(item.second, &sub, py::str(item.first), nullptr)) return false;
    }
    emit(std::move(sub), t, key, a);
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    toml::array sub;
    for (auto e : v)
      if (!to_toml(e, nullptr, "", &sub)) return false;
    emit(std::move(sub), t, key, a);
  } else {
    return false;
  }
  return true;
}

// Python's shorthands for a config's tables: tolerance = ("rel_mse", 0.01) for
// { metric = "rel_mse", value = 0.01 }; a projection of kind "fit" as a name
// ("wi") for { name = "wi" } or a 2x4 matrix for { matrix = ... }.
py::object config_form(const std::string& key, const py::object& v) {
  const auto pair = [](const py::object& o) {
    return (py::isinstance<py::tuple>(o) || py::isinstance<py::list>(o)) && py::len(o) == 2 &&
           py::isinstance<py::str>(o[py::int_(0)]);
  };
  if (key == "tolerance" && pair(v)) return py::dict(py::arg("metric") = v[py::int_(0)], py::arg("value") = v[py::int_(1)]);
  if (key == "projections" && (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v))) {
    py::list out;
    for (auto e : v) {
      if (py::isinstance<py::str>(e)) out.append(py::dict(py::arg("name") = e));
      else if (py::isinstance<py::dict>(e)) out.append(e);
      else out.append(py::dict(py::arg("matrix") = e));
    }
    return out;
  }
  return v;
}

// A reader's problems as one message: "<kind>: <key>: <rule>" per line, the
// CLI's "<file>:<line>: method[i].<key>: <rule>" with the call's kind in
// front instead of the file and table.
[[noreturn]] void throw_issues(const std::string& kind, const std::vector<std::string>& issues) {
  std::string msg;
  for (const std::string& issue : issues) {
    std::string rest = issue;
    for (const std::string section : {"method", "experiment"}) {
      const std::string lead = kind + ": " + section;
      if (issue.rfind(lead, 0) == 0 && issue.size() > lead.size() && (issue[lead.size()] == '.' || issue[lead.size()] == ':')) {
        rest = issue.substr(lead.size() + (issue[lead.size()] == '.' ? 1 : 2));
        rest = kind + ": " + rest;
        break;
      }
    }
    msg += (msg.empty() ? "" : "\n") + rest;
  }
  throw std::invalid_argument(msg);
}

// Keywords that are not options of a call.
void reject_table_keys(const std::string& kind, const std::string& key) {
  if (key == "kind" || key == "label" || key == "zip")
    throw std::invalid_argument(kind + ": " + key + ": names or sweeps a config's [[method]] table; a call takes options only");
  const MethodKind* k = find_method_kind(kind);
  const std::vector<KeySpec> keys = k ? k->keys() : std::vector<KeySpec>{};
  const bool has_shrm =
      std::any_of(keys.begin(), keys.end(), [](const KeySpec& spec) { return spec.name == "shrm"; });
  if (key == "shrm" && has_shrm)
    throw std::invalid_argument(kind + ": shrm: the SHRM needs an experiment's [scene] lighting: run a config with bf.run()");
}

// The typed options of one call, as the config reader fills them.
struct MethodCall {
  const MethodKind* kind = nullptr;
  MethodVariant m;
  double metric_eps = 1e-5;
};

// Reads kw as the [[method]] table of kind `kind` (metric_eps as the
// [experiment] key; seed defaults to experiment.seed's default, 1).
MethodCall read_call(const std::string& kind, const py::kwargs& kw) {
  MethodCall call;
  call.kind = find_method_kind(kind);
  if (!call.kind) throw std::invalid_argument("kind: expected one of " + join(method_kind_names()) + ", found \"" + kind + "\"");
  toml::table method, experiment;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    reject_table_keys(kind, key);
    if (item.second.is_none()) continue;  // None: the default
    toml::table& dst = key == "metric_eps" ? experiment : method;
    const py::object v = config_form(key, py::reinterpret_borrow<py::object>(item.second));
    if (!to_toml(v, &dst, key, nullptr))
      throw std::invalid_argument(kind + ": " + key +
                                  ": expected a value a config holds (a number, string, bool, list or dict), found " +
                                  shown(item.second));
  }
  Ctx ctx;
  ctx.path = kind;
  // Every value is located at the call: its messages start with the kind.
  ctx.mark_define(method, kind);
  ctx.mark_define(experiment, kind);
  const ExperimentSettings e = read_experiment_table(experiment, ctx, kind);
  call.metric_eps = e.metric_eps;
  const Combo c = plain_combo(method);
  Reader r(ctx, c, "method", kind);
  read_method_table(r, *call.kind, e.seed, call.m);
  if (!ctx.issues.empty()) throw_issues(kind, ctx.issues);
  return call;
}

}  // namespace

double checked_metric_eps(const std::string& who, double eps) {
  toml::table experiment;
  experiment.insert_or_assign("metric_eps", eps);
  Ctx ctx;
  ctx.path = who;
  ctx.mark_define(experiment, who);
  const ExperimentSettings e = read_experiment_table(experiment, ctx, who);
  if (!ctx.issues.empty()) throw_issues(who, ctx.issues);
  return e.metric_eps;
}

namespace {

json choice_record(const SizeChoice& c) {
  json tried = json::array();
  for (const auto& t : c.tried) tried.push_back({{"value", t.value}, {"view_order", t.view_order}, {"error", t.error}});
  return {{"knob", c.knob},   {"value", c.value},     {"view_order", c.view_order}, {"texture_size", c.texture_size},
          {"metric", c.metric}, {"error", c.error},   {"reached", c.reached},       {"tried", tried}};
}

// Runs a kind on the samples (and the BRDF, for the tabulating kinds) as the
// runner's execute_run does, and reports as a results row: metrics on the
// samples (when given), errors after each term, evaluations, and the entries
// the run adds to run.json as `info`.
std::shared_ptr<PyFactorization> run_kind(const MethodCall& call, const BrdfPtr& brdf,
                                          const std::shared_ptr<const SampleSet>& samples) {
  const MethodVariant& m = call.m;
  if (m.tolerance && !samples)
    throw std::invalid_argument(m.kind + ": tolerance: needs samples (the error is measured on them)");
  std::shared_ptr<PyFactorization> p;
  {
    LongCall long_call;
    const auto t0 = Clock::now();
    const SampleSet none;
    const SampleSet& s = samples ? *samples : none;
    const LogTransform lt = samples ? LogTransform::of(s, call.metric_eps) : LogTransform{Rgb::Ones(), call.metric_eps};
    // The azimuthal-invariance test, as the runner makes it for every run (SH-K's reduction reads it).
    const IsotropyResult iso = brdf ? test_isotropy(*brdf) : IsotropyResult{};
    const Plan plan;
    const PlannedRun run;
    BrdfVariant b;
    b.brdf = brdf;
    const RunContext c{plan, run, b, m, s, lt, iso, {}, [] { return std::shared_ptr<const SphereRender>(); }};
    MethodOutcome out = call.kind->run(c);
    const double seconds = since(t0);
    p = wrap(out.result);
    p->seconds = seconds;
    p->metric_eps = call.metric_eps;
    if (samples) p->metrics = evaluate_metrics(*out.result, s, lt);
    p->evaluations = out.evaluations;
    p->info = out.record;
    call.kind->report_call(c, out, samples != nullptr, p->errors_after_term, p->info);  // the kind's extras
    if (brdf) p->info["isotropic"] = iso.isotropic;
    if (out.choice) p->info["size_choice"] = choice_record(*out.choice);
    if (!out.notes.empty()) p->info["notes"] = out.notes;
  }
  return p;
}

std::shared_ptr<PyFactorization> run_on_samples(const std::string& kind, const std::shared_ptr<SampleSet>& s,
                                                const py::kwargs& kw) {
  const MethodCall call = read_call(kind, kw);
  return run_kind(call, nullptr, s);
}

std::shared_ptr<PyFactorization> run_on_brdf(const std::string& kind, const PyBrdf& b, const py::object& samples,
                                             const py::kwargs& kw) {
  const MethodCall call = read_call(kind, kw);
  return run_kind(call, b.brdf, samples.is_none() ? nullptr : samples.cast<std::shared_ptr<SampleSet>>());
}

// ------------------------------------------------------------------ refine

// refine(): the refinement stage on its own, with RefineOptions' field names
// (not a config table: a config refines through a kind's refine keys).
std::shared_ptr<PyFactorization> run_refine(const PyFactorization& start, const SampleSet& s, const py::kwargs& kw) {
  auto h = std::dynamic_pointer_cast<const HomomorphicFactorization>(start.f);
  if (!h)
    throw std::invalid_argument("refine: expected a factorization of mccool, fit or search, found method " + start.f->method());
  toml::table t;
  for (auto item : kw) {
    const std::string key = py::str(item.first);
    if (item.second.is_none()) continue;
    if (!to_toml(item.second, &t, key, nullptr))
      throw std::invalid_argument("refine: " + key + ": expected a number or a string, found " + shown(item.second));
  }
  Ctx ctx;
  ctx.path = "refine";
  ctx.mark_define(t, "refine");
  const Combo c = plain_combo(t);
  Reader r(ctx, c, "method", "refine");
  RefineOptions ro;
  ro.objective = r.choice("objective", ro.objective, {"linear", "cosine", "blend"});
  ro.blend_weight = r.number("blend_weight", ro.blend_weight, 0.0, RefineOptions::kMaxWeight);
  ro.max_iterations = static_cast<int>(r.integer("max_iterations", ro.max_iterations, 1, 100000));
  ro.smoothing = r.number("smoothing", ro.smoothing, 0.0, RefineOptions::kMaxWeight);
  ro.threads = static_cast<int>(r.integer("threads", ro.threads, 0, 1024));
  ro.function_tolerance = r.number("function_tolerance", ro.function_tolerance, 0.0, kInf, true);
  const std::string ls = r.choice("linear_solver", "auto", {"auto", "suitesparse", "eigen_sparse", "cgnr"});
  ro.linear_solver = ls == "suitesparse"    ? RefineOptions::LinearSolver::SuiteSparse
                     : ls == "eigen_sparse" ? RefineOptions::LinearSolver::EigenSparse
                     : ls == "cgnr"         ? RefineOptions::LinearSolver::CGNR
                                            : RefineOptions::LinearSolver::Auto;
  const double metric_eps = r.number("metric_eps", 1e-5, 0.0, 1.0, true);
  r.finish({"objective", "blend_weight", "max_iterations", "smoothing", "threads", "function_tolerance",
            "linear_solver", "metric_eps"},
           "refine()");
  if (!ctx.issues.empty()) throw_issues("refine", ctx.issues);
  std::shared_ptr<PyFactorization> p;
  {
    LongCall long_call;
    const auto t0 = Clock::now();
    RefineReport rep;
    auto out = refine(*h, s, ro, &rep);
    p = wrap(out);
    p->seconds = since(t0);
    p->metric_eps = metric_eps;
    p->metrics = evaluate_metrics(*out, s, LogTransform::of(s, metric_eps));
    p->evaluations = rep.iterations;
    p->info = {{"refinement",
                {{"objective", rep.objective},     {"linear_solver", rep.linear_solver}, {"iterations", rep.iterations},
                 {"seconds", rep.seconds},         {"initial_cost", rep.initial_cost},   {"final_cost", rep.final_cost},
                 {"termination", rep.termination}, {"parameters", rep.parameters},       {"residuals", rep.residuals},
                 {"texels_added", rep.texels_added}, {"blend_weight", ro.blend_weight}, {"smoothing", ro.smoothing}}}};
  }
  return p;
}

}  // namespace

void bind_methods(py::module_& m) {
  // One function per registered kind (bf.<kind>, '-' as '_'), its docstring
  // from the kind's summary and key docs (experiments/methods/method_kind.h).
  static const std::vector<MethodCallSpec> specs = method_call_specs();  // outlives the module's docstrings
  for (const MethodCallSpec& spec : specs) {
    const std::string kind = spec.kind;
    if (spec.input == "brdf")
      m.def(
          spec.function.c_str(),
          [kind](const PyBrdf& b, const py::object& samples, const py::kwargs& kw) {
            return run_on_brdf(kind, b, samples, kw);
          },
          py::arg("brdf"), py::arg("samples") = py::none(), spec.doc.c_str());
    else
      m.def(
          spec.function.c_str(),
          [kind](const std::shared_ptr<SampleSet>& s, const py::kwargs& kw) { return run_on_samples(kind, s, kw); },
          py::arg("samples"), spec.doc.c_str());
  }
  m.def(
      "_method_table",
      [] {
        py::list out;
        for (const MethodCallSpec& spec : method_call_specs())
          out.append(py::make_tuple(spec.kind, spec.function, spec.input));
        return out;
      },
      "[(kind, function name, \"samples\" | \"brdf\")] of every registered method kind, in order.");
  m.def(
      "_method_examples",
      [] {
        // Every registered kind with its small, fast example options (what
        // the catalogue test runs), for tests that must cover every kind.
        py::dict out;
        for (const auto& k : method_kinds()) {
          std::ostringstream js;
          js << toml::json_formatter{toml::parse(k->example())};
          out[py::str(k->name())] = to_python(json::parse(js.str()));
        }
        return out;
      },
      "{kind: example options} of every registered method kind (tests).");
  m.def("refine", &run_refine, py::arg("factorization"), py::arg("samples"),
        R"doc(refine(factorization, samples, **options) -> Factorization

Ceres refinement of a mccool/fit/search factorization in linear space
(factor/refine.h): objective ("linear" | "cosine" | "blend"), blend_weight,
max_iterations, smoothing, threads, function_tolerance, linear_solver
("auto" | "suitesparse" | "eigen_sparse" | "cgnr"), metric_eps.)doc");
}

}  // namespace bf::py_module
