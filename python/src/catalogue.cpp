// The catalogue in Python: models, presets, file formats, brdf(spec, **overrides),
// and Brdf.eval on arrays of direction pairs.
#include <cmath>

#include "brdfs/catalogue.h"
#include "common.h"

namespace bf::py_module {

namespace {

// One override value as the catalogue's "k=v" syntax writes it: numbers in
// Python's shortest round-trip form, booleans as true/false, RGB triples as r/g/b.
std::string override_text(const std::string& key, const py::handle& v) {
  // A 0-d numpy array is its scalar; other arrays are lists (numpy arrays
  // also pass the index and float checks below).
  if (py::isinstance<py::array>(v) && py::array(py::reinterpret_borrow<py::object>(v)).ndim() == 0)
    return override_text(key, v.attr("item")());
  if (py::isinstance<py::array>(v)) return override_text(key, v.attr("tolist")());
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (PyIndex_Check(v.ptr())) return py::str(py::int_(py::reinterpret_borrow<py::object>(v)));
  if (PyFloat_Check(v.ptr()) || py::hasattr(v, "__float__"))
    return py::repr(py::float_(py::reinterpret_borrow<py::object>(v)));
  if (py::isinstance<py::sequence>(v)) {
    std::string out;
    for (auto e : py::reinterpret_borrow<py::object>(v)) {
      if (py::isinstance<py::sequence>(e) && !py::isinstance<py::str>(e))
        throw std::invalid_argument("brdf: " + key + ": expected a number, a string or a list of numbers (RGB), found a nested list");
      out += (out.empty() ? "" : "/") + override_text(key, e);
    }
    return out;
  }
  throw std::invalid_argument("brdf: " + key + ": expected a number, a string, a bool or a list of numbers (RGB), found " +
                              std::string(py::str(py::type::of(v).attr("__name__"))));
}

py::array_t<double> eval_pairs(const Brdf& b, const py::handle& wi_in, const py::handle& wo_in) {
  const bool single = py::isinstance<py::array>(wi_in) ? py::array(py::reinterpret_borrow<py::object>(wi_in)).ndim() == 1
                                                        : false;
  auto wi = directions_array(wi_in, "wi");
  auto wo = directions_array(wo_in, "wo");
  const py::ssize_t ni = wi.shape(0), no = wo.shape(0);
  if (ni != no && ni != 1 && no != 1)
    throw std::invalid_argument("eval: wi has " + std::to_string(ni) + " directions and wo " + std::to_string(no) +
                                " (expected the same number, or one of them a single direction)");
  const py::ssize_t n = std::max(ni, no);
  py::array_t<double> out({n, py::ssize_t(3)});
  const double* pi = wi.data();
  const double* po = wo.data();
  double* pr = out.mutable_data();
  const py::ssize_t si = ni == 1 ? 0 : 3, so = no == 1 ? 0 : 3;
  py::ssize_t bad_i = -1, bad_o = -1;
  {
    py::gil_scoped_release release;
    for (py::ssize_t k = 0; k < n; ++k) {
      const Vec3 a(pi[k * si], pi[k * si + 1], pi[k * si + 2]);
      const Vec3 c(po[k * so], po[k * so + 1], po[k * so + 2]);
      const double la = a.norm(), lc = c.norm();
      if (!(la > 1e-12) || !std::isfinite(la)) {
        bad_i = k;
        break;
      }
      if (!(lc > 1e-12) || !std::isfinite(lc)) {
        bad_o = k;
        break;
      }
      // Unit directions (to 1e-14) are used as given, so that values at a
      // sample set's own directions are bit-identical to its values.
      const Rgb f = b.eval(std::abs(la - 1.0) <= 1e-14 ? a : Vec3(a / la), std::abs(lc - 1.0) <= 1e-14 ? c : Vec3(c / lc));
      pr[3 * k] = f[0];
      pr[3 * k + 1] = f[1];
      pr[3 * k + 2] = f[2];
    }
  }
  if (bad_i >= 0 || bad_o >= 0) {
    const bool is_i = bad_i >= 0;
    const py::ssize_t k = is_i ? bad_i : bad_o;
    throw std::invalid_argument(std::string(is_i ? "wi" : "wo") + "[" + std::to_string(is_i ? k * (si / 3) : k * (so / 3)) +
                                "]: direction must be non-zero and finite");
  }
  if (single && n == 1) return out.reshape({py::ssize_t(3)});
  return out;
}

}  // namespace

void bind_catalogue(py::module_& m) {
  py::class_<PyBrdf, std::shared_ptr<PyBrdf>>(m, "Brdf", R"doc(
A BRDF: a catalogue model or preset, a measured file, or a factorization.
Conventions (brdfs/brdf.h): local frame with the normal +z; wi towards the
light, wo towards the viewer; values in 1/sr, linear RGB, without the cosine;
0 below the horizon.)doc")
      .def(
          "eval", [](const PyBrdf& self, const py::handle& wi, const py::handle& wo) { return eval_pairs(*self.brdf, wi, wo); },
          py::arg("wi"), py::arg("wo"),
          R"doc(f(wi, wo) for arrays of directions: wi, wo (N, 3) (or one of them (3,),
used for every pair), normalized here as the CLI's eval does; returns (N, 3)
float64 RGB in 1/sr ((3,) when both are (3,)). Directions of unit length
(to 1e-14) are used as given. The GIL is released.)doc")
      .def("__call__", [](const PyBrdf& self, const py::handle& wi, const py::handle& wo) { return eval_pairs(*self.brdf, wi, wo); },
           py::arg("wi"), py::arg("wo"))
      .def_property_readonly("name", [](const PyBrdf& self) { return self.brdf->name(); })
      .def_property_readonly("reciprocal", [](const PyBrdf& self) { return self.brdf->reciprocal(); })
      .def_property_readonly("isotropic", [](const PyBrdf& self) { return self.brdf->isotropic(); })
      .def_property_readonly("bilateral", [](const PyBrdf& self) { return self.brdf->bilateral(); })
      .def_property_readonly("whole_domain", [](const PyBrdf& self) { return self.brdf->whole_domain(); },
                             "Whether eval is the BRDF over the whole domain (an interpolant of scattered "
                             "samples: only when its data declare isotropic+reciprocal+bilateral)")
      .def("to_string", [](const PyBrdf& self) { return self.brdf->to_string(); })
      .def("__repr__", [](const PyBrdf& self) { return "<brdf_factor.Brdf " + self.brdf->to_string() + ">"; });

  m.def(
      "brdf",
      [](const std::string& spec, const py::kwargs& overrides) {
        std::string full = spec;
        if (overrides.size() > 0) {
          // Appended as the CLI's "name:k=v,k=v" (after any the spec already has;
          // a file path's folders may not hold a ':' then).
          const size_t slash = spec.find_last_of('/');
          const bool has_assignments = spec.find(':', slash == std::string::npos ? 0 : slash + 1) != std::string::npos;
          full += has_assignments ? "," : ":";
          bool first = true;
          for (auto item : overrides) {
            const std::string key = py::str(item.first);
            full += (first ? "" : ",") + key + "=" + override_text(key, item.second);
            first = false;
          }
        }
        std::shared_ptr<PyBrdf> b = std::make_shared<PyBrdf>();
        py::gil_scoped_release release;  // measured files can take a while to read
        b->brdf = Catalogue::builtin().make(full, "brdf");
        return b;
      },
      py::arg("spec"),
      R"doc(brdf(spec, **overrides) -> Brdf

spec: a model or preset name ("cook-torrance", "bluepaint",
"ngan-ward/blue-acrylic"), optionally with "name:k=v,..." assignments, or a
file path (.astm, .brdf, .csv, .binary, a factorization's .json). Keyword
overrides are appended as k=v (numbers, strings, bools, RGB triples), e.g.
brdf("cook-torrance", m=0.2, kd=(0.1, 0.2, 0.3)). Unknown names and keys
raise ValueError with the CLI's message.)doc");

  m.def(
      "models",
      [] {
        py::list out;
        for (const auto& [name, info] : Catalogue::builtin().models()) {
          py::list params;
          for (const auto& p : info.params) {
            py::dict d;
            d["name"] = p.name;
            d["default"] = p.default_value;
            d["doc"] = p.doc;
            params.append(d);
          }
          py::dict d;
          d["name"] = name;
          d["description"] = info.description;
          d["params"] = params;
          out.append(d);
        }
        return out;
      },
      "Every catalogue model: list of {name, description, params: [{name, default, doc}]}, sorted by name.");
  m.def(
      "presets",
      [] {
        py::list out;
        for (const auto& [name, p] : Catalogue::builtin().presets()) {
          py::dict d;
          d["name"] = name;
          d["model"] = p.model;
          d["params"] = p.params;
          d["source"] = p.source;
          out.append(d);
        }
        return out;
      },
      "Every preset: list of {name, model, params ('k=v,...'), source}, sorted by name.");
  m.def("file_formats", [] { return Catalogue::builtin().loader_extensions(); },
        "File extensions brdf() loads (.astm, .binary, .brdf, .csv, .json).");
  m.def("data_dir", &data_dir, "Folder of the bundled data ($BRDF_FACTOR_DATA or the source tree's data/).");
}

}  // namespace bf::py_module
