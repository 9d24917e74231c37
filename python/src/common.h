// Shared pieces of the Python module brdf_factor._core: the wrapped BRDF and
// factorization objects, numpy conversions, and long calls (GIL released,
// Ctrl-C cancels).
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

// A long call (a method, a refinement, an experiment run): constructed with
// the GIL held, it releases the GIL for its lifetime. Called from Python's
// main thread (where Python runs signal handlers), it also makes Ctrl-C
// cancel the computation: SIGINT requests a cancellation (solvers/cancel.h)
// and is passed on to the handler Python installed, so the call ends with
// bf::Cancelled at its next cancellation point, which the module raises as
// KeyboardInterrupt (or whatever Python's SIGINT handler raises).
class LongCall {
 public:
  LongCall();
  ~LongCall();
  LongCall(const LongCall&) = delete;
  LongCall& operator=(const LongCall&) = delete;

 private:
  bool chained_ = false;
  std::optional<py::gil_scoped_release> release_;
};

// metric_eps of a call that scores (score(), Factorization.score()), checked
// as the config's experiment.metric_eps; messages start with `who`.
double checked_metric_eps(const std::string& who, double eps);

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

// Binding groups, one per source file.
void bind_catalogue(py::module_& m);     // catalogue.cpp: Brdf, models, presets, brdf()
void bind_samples(py::module_& m);       // samples.cpp: SampleSet and samplers
void bind_factorization(py::module_& m); // factorization.cpp: Factorization, load, metrics
void bind_methods(py::module_& m);       // methods.cpp: mccool, fit, search, svd, sh_k, sh_r, model_fit, refine
void bind_run(py::module_& m);           // run.cpp: run()
void bind_sampling(py::module_& m);      // sampling.cpp: Brdf.sample, Brdf.pdf

}  // namespace bf::py_module
