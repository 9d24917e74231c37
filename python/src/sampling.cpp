// Importance sampling from Python: Brdf.sample(wo, u) and Brdf.pdf(wi, wo)
// (factor/sampling.h), numpy in, numpy out. Every Brdf has them, so every
// Factorization does. A BRDF's sampler is built on first use for given
// options and kept for that BRDF object (the cache entry is checked against
// the object it was built for).
#include <map>
#include <mutex>
#include <tuple>

#include "common.h"
#include "factor/sampling.h"

namespace bf::py_module {

namespace {

using Key = std::tuple<const Brdf*, std::string, int, int, int>;
struct Entry {
  std::weak_ptr<const Brdf> brdf;
  std::shared_ptr<const BrdfSampler> sampler;
};

std::shared_ptr<const BrdfSampler> sampler_of(const BrdfPtr& b, const std::string& method, int view_bins,
                                              int theta_bins, int phi_bins) {
  if (method == "cosine") return cosine_sampler();
  SamplerOptions o;
  o.method = method, o.view_bins = view_bins, o.theta_bins = theta_bins, o.phi_bins = phi_bins;
  o.validate();  // OptionError -> ValueError naming the option
  static std::mutex mu;
  static std::map<Key, Entry> cache;
  const Key key{b.get(), method, view_bins, theta_bins, phi_bins};
  {
    std::lock_guard<std::mutex> lock(mu);
    for (auto it = cache.begin(); it != cache.end();) it = it->second.brdf.expired() ? cache.erase(it) : std::next(it);
    auto it = cache.find(key);
    if (it != cache.end() && it->second.brdf.lock() == b) return it->second.sampler;
  }
  auto s = make_sampler(*b, o);
  std::lock_guard<std::mutex> lock(mu);
  cache[key] = {b, s};
  return s;
}

// (N, 2) float64 of u in [0, 1); a (2,) vector is (1, 2).
py::array_t<double, py::array::c_style | py::array::forcecast> u_array(const py::handle& a) {
  auto u = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!u) throw std::invalid_argument("u: expected an array of numbers, shape (N, 2) or (2,)");
  if (u.ndim() == 1 && u.shape(0) == 2) u = u.reshape({py::ssize_t(1), py::ssize_t(2)});
  if (u.ndim() != 2 || u.shape(1) != 2)
    throw std::invalid_argument("u: expected shape (N, 2) or (2,), found " + std::to_string(u.ndim()) + " dimensions");
  const double* p = u.data();
  for (py::ssize_t k = 0; k < u.shape(0) * 2; ++k)
    if (!(p[k] >= 0.0 && p[k] < 1.0))
      throw std::invalid_argument("u[" + std::to_string(k / 2) + "][" + std::to_string(k % 2) +
                                  "]: expected a number in [0, 1), found " + std::to_string(p[k]));
  return u;
}

Vec3 unit(const double* d, const char* what, py::ssize_t k) {
  const Vec3 v(d[0], d[1], d[2]);
  const double l = v.norm();
  if (!(l > 1e-12) || !std::isfinite(l))
    throw std::invalid_argument(std::string(what) + "[" + std::to_string(k) + "]: direction must be non-zero and finite");
  return std::abs(l - 1.0) <= 1e-14 ? v : Vec3(v / l);
}

}  // namespace

void bind_sampling(py::module_& m) {
  auto cls = py::reinterpret_borrow<py::class_<PyBrdf, std::shared_ptr<PyBrdf>>>(m.attr("Brdf"));
  cls.def(
      "sample",
      [](const PyBrdf& self, const py::handle& wo_in, const py::handle& u_in, const std::string& method,
         int view_bins, int theta_bins, int phi_bins) {
        const auto wo = directions_array(wo_in, "wo");
        const auto u = u_array(u_in);
        const py::ssize_t n = u.shape(0), no = wo.shape(0);
        if (no != 1 && no != n)
          throw std::invalid_argument("wo: expected 1 or " + std::to_string(n) + " directions (one per u), found " +
                                      std::to_string(no));
        const auto s = sampler_of(self.brdf, method, view_bins, theta_bins, phi_bins);
        py::array_t<double> wi({n, py::ssize_t(3)});
        py::array_t<double> pdf(n);
        double* pw = wi.mutable_data();
        double* pp = pdf.mutable_data();
        const double* pu = u.data();
        const double* po = wo.data();
        for (py::ssize_t k = 0; k < n; ++k) {
          const py::ssize_t ko = no == 1 ? 0 : k;
          const DirectionSample d = s->sample(unit(po + 3 * ko, "wo", ko), pu[2 * k], pu[2 * k + 1]);
          pw[3 * k] = d.wi.x(), pw[3 * k + 1] = d.wi.y(), pw[3 * k + 2] = d.wi.z(), pp[k] = d.pdf;
        }
        return py::make_tuple(wi, pdf);
      },
      py::arg("wo"), py::arg("u"), py::arg("method") = "auto", py::arg("view_bins") = 16,
      py::arg("theta_bins") = 32, py::arg("phi_bins") = 64,
      R"doc(Importance-sample light directions (docs/design.md, Importance sampling):
wo (N, 3) or (3,) view directions (normalized here), u (N, 2) uniform numbers
in [0, 1); returns (wi (N, 3), pdf (N,)), pdf per solid angle, 0 where there
is no sample (wo below the horizon). method: "auto" (a model's own sampler
where one exists, else the table of f cos), "tabulated" or "cosine". The
sampler is built on first use and kept for this object.)doc")
      .def(
          "pdf",
          [](const PyBrdf& self, const py::handle& wi_in, const py::handle& wo_in, const std::string& method,
             int view_bins, int theta_bins, int phi_bins) {
            const auto wi = directions_array(wi_in, "wi");
            const auto wo = directions_array(wo_in, "wo");
            const py::ssize_t ni = wi.shape(0), no = wo.shape(0), n = std::max(ni, no);
            if ((ni != 1 && ni != n) || (no != 1 && no != n))
              throw std::invalid_argument("wi, wo: expected the same number of directions (or one of them 1), found " +
                                          std::to_string(ni) + " and " + std::to_string(no));
            const auto s = sampler_of(self.brdf, method, view_bins, theta_bins, phi_bins);
            py::array_t<double> pdf(n);
            double* pp = pdf.mutable_data();
            for (py::ssize_t k = 0; k < n; ++k) {
              const py::ssize_t ki = ni == 1 ? 0 : k, ko = no == 1 ? 0 : k;
              pp[k] = s->pdf(unit(wi.data() + 3 * ki, "wi", ki), unit(wo.data() + 3 * ko, "wo", ko));
            }
            return pdf;
          },
          py::arg("wi"), py::arg("wo"), py::arg("method") = "auto", py::arg("view_bins") = 16,
          py::arg("theta_bins") = 32, py::arg("phi_bins") = 64,
          R"doc(The density sample() draws wi with, per solid angle: wi, wo (N, 3) or (3,); returns (N,).)doc");
}

}  // namespace bf::py_module
