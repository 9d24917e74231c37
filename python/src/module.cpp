// brdf_factor._core: the module definition, exception translation and the
// shared helpers of common.h (option reading, conversions, Ctrl-C).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "brdfs/catalogue.h"
#include "common.h"
#include "experiments/config.h"
#include "experiments/config_reader.h"
#include "experiments/methods/method_kind.h"
#include "factor/export.h"

namespace bf::py_module {

void check_signals() {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) {
    PyErr_Clear();
    throw Interrupted();
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

// ------------------------------------------------------------------ Options

namespace {

std::string type_name(const py::handle& o) { return py::str(py::type::of(o).attr("__name__")); }

std::string shown(const py::handle& o) {
  std::string r = py::repr(o);
  if (r.size() > 60) r = r.substr(0, 57) + "...";
  return r + " (" + type_name(o) + ")";
}

}  // namespace

Options::Options(std::string kind, const py::kwargs& kw) : kind_(std::move(kind)) {
  for (auto item : kw) values_[py::str(item.first)] = py::reinterpret_borrow<py::object>(item.second);
}

py::object Options::take(const std::string& key) {
  read_.push_back(key);
  auto it = values_.find(key);
  if (it == values_.end()) return py::none();
  py::object o = it->second;
  values_.erase(it);
  return o;
}

void Options::fail(const std::string& message) const { throw std::invalid_argument(kind_ + ": " + message); }

void Options::type_error(const std::string& key, const std::string& expected, const py::handle& found) const {
  fail(key + ": expected " + expected + ", found " + shown(found));
}

namespace {

std::string fmt_num(double v) {  // as the config reader prints numbers
  std::ostringstream ss;
  ss.precision(12);
  ss << v;
  return ss.str();
}

std::string range_int(long long lo, long long hi) {
  if (lo == -Options::kNoLimit) return "";
  if (hi == Options::kNoLimit) return " >= " + std::to_string(lo);
  return " in " + std::to_string(lo) + ".." + std::to_string(hi);
}

std::string range_num(double lo, double hi, bool lo_open) {
  if (std::isinf(lo) && std::isinf(hi)) return "";
  if (std::isinf(hi)) return std::string(lo_open ? " > " : " >= ") + fmt_num(lo);
  return std::string(" in ") + (lo_open ? "(" : "[") + fmt_num(lo) + ", " + fmt_num(hi) + "]";
}

}  // namespace

namespace {
// The range the config reader enforces for `key` of method kind `kind`, from
// the method catalogue (experiments/methods/): a keyword argument is held to
// the same range as the config key, stated in one place. nullptr for keys the
// catalogue does not describe (their range is the caller's).
const KeySpec* catalogue_spec(const std::string& kind, const std::string& key, KeySpec::Type type) {
  const MethodKind* k = find_method_kind(kind);
  if (!k) return nullptr;
  static thread_local std::vector<KeySpec> keys;
  keys = k->keys();
  for (const KeySpec& s : keys)
    if (s.name == key && s.type == type) return &s;
  return nullptr;
}
}  // namespace

int Options::integer(const std::string& key, int def, long long lo, long long hi) {
  py::object o = take(key);
  if (o.is_none()) return def;
  if (const KeySpec* s = catalogue_spec(kind_, key, KeySpec::Type::Integer)) {
    lo = s->int_lo;
    hi = s->int_hi >= kIntMax ? kNoLimit : s->int_hi;
  }
  const std::string range = range_int(lo, hi);
  // bool is an int subclass in Python; numpy integers have __index__.
  if (py::isinstance<py::bool_>(o) || !PyIndex_Check(o.ptr())) type_error(key, "an integer" + range, o);
  const py::int_ i(o);
  if (range.empty()) {
    if (i < py::int_(-2147483647LL) || i > py::int_(2147483647LL))
      fail(key + ": expected an integer of at most 2^31 - 1 in magnitude, found " + std::string(py::str(o)));
  } else if (i < py::int_(lo) || i > py::int_(hi)) {
    fail(key + ": expected an integer" + range + ", found " + std::string(py::str(o)));
  }
  return i.cast<int>();
}

uint64_t Options::seed(const std::string& key, uint64_t def) {
  py::object o = take(key);
  if (o.is_none()) return def;
  if (py::isinstance<py::bool_>(o) || !PyIndex_Check(o.ptr())) type_error(key, "an integer >= 0", o);
  const py::int_ i(o);
  if (i < py::int_(0) || i > py::int_(9223372036854775807LL))
    fail(key + ": expected an integer >= 0, found " + std::string(py::str(o)));
  return i.cast<uint64_t>();
}

double Options::number(const std::string& key, double def, double lo, double hi, bool lo_open) {
  py::object o = take(key);
  if (o.is_none()) return def;
  if (const KeySpec* s = catalogue_spec(kind_, key, KeySpec::Type::Number)) {
    lo = s->lo;
    hi = s->hi;
    lo_open = s->lo_open;
  }
  const std::string range = range_num(lo, hi, lo_open);
  if (py::isinstance<py::bool_>(o) || !(PyFloat_Check(o.ptr()) || PyIndex_Check(o.ptr()) ||
                                        py::hasattr(o, "__float__")))
    type_error(key, "a number" + range, o);
  const double v = py::float_(o).cast<double>();
  if (!std::isfinite(v) && range.empty()) fail(key + ": expected a finite number, found " + std::string(py::str(o)));
  if (!std::isfinite(v) || (lo_open ? v <= lo : v < lo) || v > hi)
    fail(key + ": expected a number" + range + ", found " + fmt_num(v));
  return v;
}

bool Options::boolean(const std::string& key, bool def) {
  py::object o = take(key);
  if (o.is_none()) return def;
  if (!py::isinstance<py::bool_>(o) && !py::isinstance(o, py::module_::import("numpy").attr("bool_")))
    type_error(key, "True or False", o);
  return o.cast<bool>();
}

std::string Options::text(const std::string& key, const std::string& def) {
  py::object o = take(key);
  if (o.is_none()) return def;
  if (!py::isinstance<py::str>(o)) type_error(key, "a string", o);
  return o.cast<std::string>();
}

std::string Options::choice(const std::string& key, const std::string& def, const std::vector<std::string>& allowed) {
  const bool given = has(key);
  const std::string v = text(key, def);
  if (given && std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
    std::string list;
    for (size_t i = 0; i < allowed.size(); ++i) list += (i ? ", " : "") + std::string("\"") + allowed[i] + "\"";
    fail(key + ": expected one of " + list + ", found \"" + v + "\"");
  }
  return v;
}

std::vector<std::string> Options::texts(const std::string& key) {
  py::object o = take(key);
  std::vector<std::string> out;
  if (o.is_none()) return out;
  if (py::isinstance<py::str>(o) || !py::isinstance<py::sequence>(o)) type_error(key, "a list of strings", o);
  for (auto e : o) {
    if (!py::isinstance<py::str>(e)) type_error(key, "a list of strings, an element", e);
    out.push_back(e.cast<std::string>());
  }
  return out;
}

py::object Options::object(const std::string& key) { return take(key); }

void Options::finish() {
  if (values_.empty()) return;
  std::vector<std::string> accepted = read_;
  std::sort(accepted.begin(), accepted.end());
  accepted.erase(std::unique(accepted.begin(), accepted.end()), accepted.end());
  std::string list;
  for (size_t i = 0; i < accepted.size(); ++i) list += (i ? ", " : "") + accepted[i];
  std::string msg;
  for (const auto& [key, value] : values_) {
    msg += (msg.empty() ? "" : "; ") + std::string("unknown option '") + key + "'" + did_you_mean(key, accepted);
  }
  fail(msg + " (accepted: " + list + ")");
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
    } catch (const bp::Interrupted&) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
    } catch (const bf::ConfigError& e) {
      py::object inst = py::reinterpret_borrow<py::object>(config_error)(e.what());
      inst.attr("messages") = py::cast(e.messages());
      PyErr_SetObject(config_error.ptr(), inst.ptr());
    }
  });
  bp::bind_catalogue(m);
  bp::bind_samples(m);
  bp::bind_factorization(m);
  bp::bind_methods(m);
  bp::bind_run(m);
}
