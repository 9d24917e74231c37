// Sample sets in Python: the catalogue's samplers, sample-list CSV files,
// measured samples, and sets built from numpy arrays. wi, wo, value, weight and
// valid are read-only numpy views of the C++ vectors (no copies).
#include <cmath>
#include <limits>
#include <optional>

#include "brdfs/measured.h"
#include "brdfs/sample_csv.h"
#include "common.h"

namespace bf::py_module {

namespace {

using SamplesPtr = std::shared_ptr<SampleSet>;

// Read-only numpy view of `count` x `cols` doubles at `data`, kept alive by `owner`.
py::array view(const py::handle& owner, const void* data, py::dtype dt, std::vector<py::ssize_t> shape,
               std::vector<py::ssize_t> strides) {
  py::array a(dt, shape, strides, data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::array vec3_view(const py::object& owner, const std::vector<Vec3>& v) {
  return view(owner, v.data(), py::dtype::of<double>(), {py::ssize_t(v.size()), 3}, {py::ssize_t(sizeof(Vec3)), 8});
}

// "(3, 2)" for an array, the type's name for anything else (messages).
std::string found_shape(const py::handle& in, const py::array& a) {
  if (!a) return std::string(py::str(py::type::of(in).attr("__name__")));
  std::string shape = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
  return shape + (a.ndim() == 1 ? ",)" : ")");
}

// Unit length, kept as given when already unit (to 1e-14); scaled by the
// largest component first, so that a finite non-zero vector whose squared
// norm over- or underflows (1e300, 1e-300) is still a direction.
void normalize_direction(Vec3& w) {
  const double l = w.norm();
  if (std::abs(l - 1.0) <= 1e-14) return;
  if (std::isfinite(l) && l > 1e-150) {
    w /= l;
    return;
  }
  const double m = w.cwiseAbs().maxCoeff();
  if (!(m > 0.0) || !std::isfinite(m)) {
    w.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  const Vec3 u = w / m;
  w = u / u.norm();
}

SamplesPtr from_arrays(const py::handle& wi_in, const py::handle& wo_in, const py::handle& value_in,
                       const py::object& weight_in, const std::string& description,
                       const std::string& symmetries) {
  const Symmetries declared = parse_symmetries(symmetries, "SampleSet(symmetries=...)");
  auto wi = directions_array(wi_in, "wi");
  auto wo = directions_array(wo_in, "wo");
  auto value = directions_array(value_in, "value");
  const py::ssize_t n = wi.shape(0);
  if (wo.shape(0) != n || value.shape(0) != n)
    throw std::invalid_argument("SampleSet: wi, wo and value must have the same number of rows, found " +
                                std::to_string(n) + ", " + std::to_string(wo.shape(0)) + ", " +
                                std::to_string(value.shape(0)));
  if (n == 0) throw std::invalid_argument("SampleSet: expected at least one sample, found 0 rows");
  // No weight: the set has none (every weight 1, SampleSet::weight_of), never
  // a vector read from an array that does not hold n values.
  std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>> weight;
  if (!weight_in.is_none()) {
    auto w = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(weight_in);
    if (!w || w.ndim() != 1 || w.shape(0) != n) {
      PyErr_Clear();
      throw std::invalid_argument("SampleSet: weight: expected shape (" + std::to_string(n) +
                                  ",) (one per sample), found " + found_shape(weight_in, w));
    }
    weight = std::move(w);
  }
  auto s = std::make_shared<SampleSet>();
  s->wi.resize(n);
  s->wo.resize(n);
  s->value.resize(n);
  std::copy_n(wi.data(), 3 * n, s->wi.front().data());
  std::copy_n(wo.data(), 3 * n, s->wo.front().data());
  std::copy_n(value.data(), 3 * n, s->value.front().data());
  for (py::ssize_t k = 0; k < n; ++k) {
    // Directions are normalized as in Brdf.eval (unit ones kept as given); zero
    // and non-finite ones become NaN and are masked by validate() as below the horizon.
    normalize_direction(s->wi[k]);
    normalize_direction(s->wo[k]);
  }
  if (weight) s->weight.assign(weight->data(), weight->data() + n);
  s->description = description;
  s->symmetries = declared;
  s->validate();
  return s;
}

}  // namespace

void bind_samples(py::module_& m) {
  py::class_<SampleSet, SamplesPtr>(m, "SampleSet", R"doc(
BRDF samples: direction pairs (wi, wo), RGB values in 1/sr, optional weights
and a validity mask (invalid values, directions below the horizon and bad
weights are masked, never used by fits and metrics).)doc")
      .def(py::init(&from_arrays), py::arg("wi"), py::arg("wo"), py::arg("value"), py::arg("weight") = py::none(),
           py::arg("description") = "arrays", py::arg("symmetries") = "none",
           R"doc(SampleSet(wi, wo, value, weight=None, description="arrays", symmetries="none")

wi, wo: (N, 3) directions (normalized here); value: (N, 3) RGB in 1/sr;
weight: (N,) >= 0 or None (all 1). The arrays are copied once into the set.
symmetries: what the data guarantee of the BRDF they sample, "none" or names
joined by '+' (isotropic, reciprocal, bilateral).)doc")
      .def("__len__", &SampleSet::size)
      .def_property_readonly("wi", [](const py::object& self) { return vec3_view(self, self.cast<const SampleSet&>().wi); },
                             "(N, 3) float64 view, read-only")
      .def_property_readonly("wo", [](const py::object& self) { return vec3_view(self, self.cast<const SampleSet&>().wo); },
                             "(N, 3) float64 view, read-only")
      .def_property_readonly(
          "value",
          [](const py::object& self) {
            const auto& v = self.cast<const SampleSet&>().value;
            return view(self, v.data(), py::dtype::of<double>(), {py::ssize_t(v.size()), 3},
                        {py::ssize_t(sizeof(Rgb)), 8});
          },
          "(N, 3) float64 view (1/sr), read-only")
      .def_property_readonly(
          "weight",
          [](const py::object& self) -> py::object {
            const auto& w = self.cast<const SampleSet&>().weight;
            if (w.empty()) return py::none();
            return view(self, w.data(), py::dtype::of<double>(), {py::ssize_t(w.size())}, {8});
          },
          "(N,) float64 view, or None when every weight is 1")
      .def_property_readonly(
          "valid",
          [](const py::object& self) {
            const auto& v = self.cast<const SampleSet&>().valid;
            return view(self, v.data(), py::dtype("bool"), {py::ssize_t(v.size())}, {1});
          },
          "(N,) bool view: samples used by fits and metrics")
      .def_property_readonly("valid_count", &SampleSet::valid_count)
      .def_readonly("description", &SampleSet::description)
      .def_property_readonly("symmetries", [](const SampleSet& s) { return s.symmetries.to_string(); },
                             "What the data declare: \"none\" or names joined by '+' (isotropic, reciprocal, bilateral)")
      .def("summary", &SampleSet::summary)
      .def("compacted", [](const SampleSet& s) { return std::make_shared<SampleSet>(s.compacted()); },
           "A new set with only the valid samples.")
      .def(
          "write_csv", [](const SampleSet& s, const std::string& path) { write_sample_csv(s, path); }, py::arg("path"),
          "Writes the set as a sample-list CSV (what `brdf-factor sample` writes).")
      .def("__repr__", [](const SampleSet& s) { return "<brdf_factor.SampleSet " + s.summary() + ">"; });

  m.def(
      "sample_grid",
      [](const PyBrdf& b, int resolution) {
        py::gil_scoped_release release;
        return std::make_shared<SampleSet>(sample_grid(*b.brdf, resolution));
      },
      py::arg("brdf"), py::arg("resolution") = 16,
      "Regular res^4 parabolic grid (resolution 16: 43,264 pairs), as sampling kind \"grid\".");
  m.def(
      "sample_stratified",
      [](const PyBrdf& b, size_t count, uint64_t seed) {
        py::gil_scoped_release release;
        return std::make_shared<SampleSet>(sample_stratified(*b.brdf, count, seed));
      },
      py::arg("brdf"), py::arg("count"), py::arg("seed") = 1,
      "count pairs, stratified and uniform in solid angle, deterministic for a seed (sampling kind \"stratified\").");
  m.def(
      "read_samples",
      [](const std::string& path) {
        py::gil_scoped_release release;
        return std::make_shared<SampleSet>(read_sample_csv(path));
      },
      py::arg("path"), "A sample-list CSV (theta_i,phi_i,theta_o,phi_o,r,g,b[,weight]; sampling kind \"file\").");
  m.def(
      "measured_samples",
      [](const PyBrdf& b) {
        py::gil_scoped_release release;
        return std::make_shared<SampleSet>(measured_samples(*b.brdf));
      },
      py::arg("brdf"), "The raw samples of a measured BRDF (sampling kind \"measured\").");
  m.def(
      "evaluate",
      [](const PyBrdf& b, const SampleSet& s) {
        auto out = std::make_shared<SampleSet>(s);
        py::gil_scoped_release release;
        evaluate_into(*b.brdf, *out);
        return out;
      },
      py::arg("brdf"), py::arg("samples"), "A copy of samples with the values of brdf at its direction pairs.");
}

}  // namespace bf::py_module
