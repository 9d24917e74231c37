// brdf_factor._core: the module definition, exception translation and the
// shared helpers of common.h (conversions, long calls and Ctrl-C).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "brdfs/catalogue.h"
#include "common.h"
#include "experiments/plan/plan.h"
#include "experiments/run/interrupt.h"
#include "factor/export.h"
#include "solvers/cancel.h"

#include <signal.h>

namespace bf::py_module {

// ------------------------------------------------------------------ long calls

namespace {

int g_chained = 0;              // LongCalls with the SIGINT handler below installed (under the GIL)
struct sigaction g_python_sigint;  // the handler they replaced (Python's)

extern "C" void on_sigint(int sig, siginfo_t* info, void* context) {
  request_cancel();
  const struct sigaction& prev = g_python_sigint;
  if (prev.sa_flags & SA_SIGINFO) {
    if (prev.sa_sigaction) prev.sa_sigaction(sig, info, context);
  } else if (prev.sa_handler != SIG_DFL && prev.sa_handler != SIG_IGN) {
    prev.sa_handler(sig);
  }
}

bool in_main_thread() {
  py::module_ threading = py::module_::import("threading");
  return threading.attr("current_thread")().is(threading.attr("main_thread")());
}

}  // namespace

LongCall::LongCall() {
  if (g_chained > 0) {
    ++g_chained;
    chained_ = true;
  } else if (in_main_thread()) {
    struct sigaction current {};
    ::sigaction(SIGINT, nullptr, &current);
    // Only over a handler that is a function (Python's): SIG_IGN means Ctrl-C
    // is ignored, SIG_DFL that it ends the process anyway.
    const bool handled = (current.sa_flags & SA_SIGINFO) ? current.sa_sigaction != nullptr
                                                         : current.sa_handler != SIG_DFL && current.sa_handler != SIG_IGN;
    if (handled) {
      clear_cancel();
      struct sigaction sa {};
      sa.sa_sigaction = on_sigint;
      sigemptyset(&sa.sa_mask);
      sa.sa_flags = SA_SIGINFO | SA_ONSTACK;
      ::sigaction(SIGINT, &sa, &g_python_sigint);
      g_chained = 1;
      chained_ = true;
    }
  }
  release_.emplace();
}

LongCall::~LongCall() {
  release_.reset();  // the GIL again: g_chained is guarded by it
  if (chained_ && --g_chained == 0) {
    ::sigaction(SIGINT, &g_python_sigint, nullptr);
    clear_cancel();
  }
}

py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

nlohmann::json to_json(const py::handle& o) {
  const std::string s = py::str(py::module_::import("json").attr("dumps")(o));
  return nlohmann::json::parse(s);
}

py::dict metrics_dict(const Metrics& m) {
  py::dict d;
  d["rel_mse"] = m.rel_mse;
  d["rel_mae"] = m.rel_mae;
  d["rel_max"] = m.rel_max;
  d["lin_rmse"] = m.lin_rmse;
  d["lin_mae"] = m.lin_mae;
  d["lin_max"] = m.lin_max;
  d["cos_rmse"] = m.cos_rmse;
  d["samples"] = m.samples;
  return d;
}

py::array_t<double, py::array::c_style | py::array::forcecast> directions_array(const py::handle& a,
                                                                               const std::string& what) {
  using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;
  if (!py::isinstance<py::array>(a) && !py::isinstance<py::sequence>(a))
    throw std::invalid_argument(what + ": expected an (N, 3) array of directions, found " +
                                std::string(py::str(py::type::of(a).attr("__name__"))));
  Arr arr = Arr::ensure(a);
  if (!arr) {
    PyErr_Clear();
    throw std::invalid_argument(what + ": expected an (N, 3) array of numbers");
  }
  if (arr.ndim() == 1 && arr.shape(0) == 3) arr = arr.reshape({py::ssize_t(1), py::ssize_t(3)});
  if (arr.ndim() != 2 || arr.shape(1) != 3) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < arr.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(arr.shape(d));
    shape += arr.ndim() == 1 ? ",)" : ")";
    throw std::invalid_argument(what + ": expected shape (N, 3) or (3,), found " + shape);
  }
  return arr;
}

}  // namespace bf::py_module

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
  namespace bp = bf::py_module;
  m.doc() = "brdf-factor's C++ core (see the brdf_factor package and docs/python.md)";
  m.attr("__version__") = BF_PYTHON_VERSION;
  // The factorization sidecar (.json) loads wherever a BRDF spec is accepted,
  // as in the CLI.
  static bool registered = false;
  if (!registered) {
    bf::register_export_loader(bf::Catalogue::global());
    registered = true;
  }
  // std::invalid_argument -> ValueError and std::runtime_error -> RuntimeError
  // (pybind11's defaults) carry what() unchanged: the CLI prints the same text
  // after "brdf-factor: ". Config errors get their own ValueError subclass.
  // ConfigError(ValueError): str() is the CLI's text (later lines prefixed
  // "brdf-factor: " as the CLI prints them), .messages the problems one by one.
  static py::handle config_error = py::exception<bf::ConfigError>(m, "ConfigError", PyExc_ValueError).release();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const bf::Cancelled&) {
      // Ctrl-C during a LongCall: Python's SIGINT handler (KeyboardInterrupt
      // unless replaced) was tripped by the signal; a call cancelled without
      // one (in another thread) raises KeyboardInterrupt itself.
      if (PyErr_CheckSignals() == 0) PyErr_SetNone(PyExc_KeyboardInterrupt);
    } catch (const bf::Interrupted& e) {
      // bf.run stopped by SIGINT (the runner's own handler): what() says what was kept.
      PyErr_SetString(PyExc_KeyboardInterrupt, e.what());
    } catch (const bf::ConfigError& e) {
      py::object inst = py::reinterpret_borrow<py::object>(config_error)(e.what());
      inst.attr("messages") = py::cast(e.messages());
      PyErr_SetObject(config_error.ptr(), inst.ptr());
    }
  });
  bp::bind_catalogue(m);
  bp::bind_sampling(m);
  bp::bind_samples(m);
  bp::bind_factorization(m);
  bp::bind_methods(m);
  bp::bind_run(m);
}
