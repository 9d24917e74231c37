// Shared pieces of the Python module brdf_factor._core: the wrapped BRDF and
// factorization objects, numpy conversions, keyword-option reading with the
// configs' rules, and Ctrl-C handling around long calls.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/sampleset.h"
#include "factor/factorization.h"
#include "factor/metrics.h"

namespace bf::py_module {

namespace py = pybind11;

// A BRDF held by Python (brdf_factor.Brdf). Any catalogue model, preset,
// measured file, or factorization.
struct PyBrdf {
  BrdfPtr brdf;
  virtual ~PyBrdf() = default;
};

// A factorization returned by a method (brdf_factor.Factorization): the
// approximation plus what the method reported about it.
struct PyFactorization : PyBrdf {
  FactorizationPtr f;
  // Metrics on the samples it was fitted to (or given for scoring); empty for
  // a tabulating method called without samples or a reloaded export.
  std::optional<Metrics> metrics;
  double metric_eps = 1e-5;
  std::vector<double> errors_after_term;  // homomorphic: rel_mse after each term (fit data)
  double seconds = 0;                      // wall time of the method (refinement included)
  int evaluations = 0;                     // search: inner-loop fits; model-fit: LM iterations
  nlohmann::json info = nlohmann::json::object();  // method-specific record (search terms, refinement, ...)
};

// The Python object of a factorization (no report yet).
std::shared_ptr<PyFactorization> wrap(FactorizationPtr f);

// Raised (as KeyboardInterrupt) when Ctrl-C arrives during a long call that can notice it.
struct Interrupted : std::exception {
  const char* what() const noexcept override { return "interrupted"; }
};
// With the GIL released: takes it, runs pending Python signal handlers, and
// throws Interrupted if one raised (Ctrl-C). Call only from the thread that
// released the GIL.
void check_signals();

// nlohmann::json <-> Python objects (through the json module: small documents only).
py::object to_python(const nlohmann::json& j);
nlohmann::json to_json(const py::handle& o);
py::dict metrics_dict(const Metrics& m);

// An (N, 3) float64 C-contiguous view of `a` (a (3,) vector is (1, 3)); copies
// only when the dtype or layout differ. `what` names the argument in errors.
py::array_t<double, py::array::c_style | py::array::forcecast> directions_array(const py::handle& a,
                                                                               const std::string& what);
// A SampleSet held by Python shares its arrays with numpy: wi, wo, value are
// (N, 3) views into the vectors (Eigen's 3-vectors are 3 packed doubles).
static_assert(sizeof(Vec3) == 3 * sizeof(double) && sizeof(Rgb) == 3 * sizeof(double),
              "SampleSet arrays are exposed as (N, 3) views");

// Keyword options of one method, read into an options struct by name. Types
// are checked here ("<kind>: <key>: expected ..., found ..."); ranges and rules
// are the structs' validate(), as in the configs. finish() rejects every key
// not read, naming it (with a close accepted key, if any).
class Options {
 public:
  Options(std::string kind, const py::kwargs& kw);
  bool has(const std::string& key) const { return values_.count(key) > 0; }
  // Ranges are the config reader's (experiments/config.cpp), worded as it
  // words them ("expected an integer in 1..64, found 0", "expected a number
  // >= 0, found -1"), so a range violation reads as in the CLI's message.
  static constexpr long long kNoLimit = std::numeric_limits<long long>::max();
  int integer(const std::string& key, int def, long long lo = -kNoLimit, long long hi = kNoLimit);
  uint64_t seed(const std::string& key, uint64_t def);
  double number(const std::string& key, double def, double lo = -std::numeric_limits<double>::infinity(),
                double hi = std::numeric_limits<double>::infinity(), bool lo_open = false);
  bool boolean(const std::string& key, bool def);
  std::string text(const std::string& key, const std::string& def);
  std::string choice(const std::string& key, const std::string& def, const std::vector<std::string>& allowed);
  std::vector<std::string> texts(const std::string& key);
  py::object object(const std::string& key);  // None when absent
  // Throws std::invalid_argument listing the unknown keys.
  void finish();
  // Throws std::invalid_argument "<kind>: <message>" (for a validate() failure).
  [[noreturn]] void fail(const std::string& message) const;
  const std::string& kind() const { return kind_; }

 private:
  py::object take(const std::string& key);
  [[noreturn]] void type_error(const std::string& key, const std::string& expected, const py::handle& found) const;
  std::string kind_;
  std::map<std::string, py::object> values_;
  std::vector<std::string> read_;
};

// Calls f (a validate()) and rethrows its std::invalid_argument prefixed with "<kind>: ".
template <class F>
void validated(const Options& o, F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    o.fail(e.what());
  }
}

// Binding groups, one per source file.
void bind_catalogue(py::module_& m);     // catalogue.cpp: Brdf, models, presets, brdf()
void bind_samples(py::module_& m);       // samples.cpp: SampleSet and samplers
void bind_factorization(py::module_& m); // factorization.cpp: Factorization, load, metrics
void bind_methods(py::module_& m);       // methods.cpp: mccool, fit, search, svd, sh_k, sh_r, model_fit, refine
void bind_run(py::module_& m);           // run.cpp: run()

}  // namespace bf::py_module
