#include "brdfs/symmetry.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "brdfs/sampleset.h"

namespace bf {

std::string Symmetries::to_string() const {
  std::string s;
  auto add = [&](bool on, const char* name) {
    if (!on) return;
    if (!s.empty()) s += "+";
    s += name;
  };
  add(isotropic, "isotropic");
  add(reciprocal, "reciprocal");
  add(bilateral, "bilateral");
  return s.empty() ? "none" : s;
}

Symmetries parse_symmetries(const std::string& text, const std::string& what) {
  const std::string accepted = "expected \"none\" or names joined by '+' (isotropic, reciprocal, bilateral)";
  if (text == "none") return {};
  Symmetries s;
  size_t start = 0;
  while (true) {
    const size_t plus = text.find('+', start);
    const std::string name = text.substr(start, plus == std::string::npos ? std::string::npos : plus - start);
    bool* slot = name == "isotropic" ? &s.isotropic : name == "reciprocal" ? &s.reciprocal
                 : name == "bilateral" ? &s.bilateral : nullptr;
    if (!slot) throw std::invalid_argument(what + ": " + accepted + ", found \"" + text + "\" (\"" + name + "\" is not a symmetry)");
    if (*slot) throw std::invalid_argument(what + ": " + accepted + ", found \"" + text + "\" (\"" + name + "\" twice)");
    *slot = true;
    if (plus == std::string::npos) break;
    start = plus + 1;
  }
  return s;
}

Symmetries symmetries_of(const Brdf& brdf) { return {brdf.isotropic(), brdf.reciprocal(), brdf.bilateral()}; }

std::string OrbitInfo::describe() const {
  std::string how = std::to_string(rotations) + (rotations == 1 ? " rotation" : " rotations");
  if (orbit_size > rotations) how += orbit_size / rotations == 4 ? " x swap x mirror" : " x swap or mirror";
  return "orbit of " + std::to_string(orbit_size) + " per sample (" + how + "): " + std::to_string(samples_in) +
         " -> " + std::to_string(samples_out) + " samples";
}

SampleSet expand_orbit(const SampleSet& s, const Symmetries& sym, const OrbitOptions& o, OrbitInfo* info) {
  if (o.max_rotations < 1) throw std::invalid_argument("orbit: max_rotations must be >= 1, found " + std::to_string(o.max_rotations));
  const size_t n = s.valid_count();
  const int m = (sym.reciprocal ? 2 : 1) * (sym.bilateral ? 2 : 1);
  int R = 1;
  if (sym.isotropic && n > 0) {
    const size_t fit = o.budget / (n * static_cast<size_t>(m));
    R = static_cast<int>(std::clamp<size_t>(fit, 1, static_cast<size_t>(o.max_rotations)));
  }
  const int G = R * m;
  SampleSet out;
  out.description = s.description;
  out.wi.reserve(n * G);
  out.wo.reserve(n * G);
  out.value.reserve(n * G);
  out.weight.reserve(n * G);
  const double golden = 0.6180339887498949;
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    const double w = s.weight_of(k) / G;
    const double u = sym.isotropic ? std::fmod(static_cast<double>(k) * golden, 1.0) : 0.0;
    for (int j = 0; j < R; ++j) {
      const double a = sym.isotropic ? 2.0 * std::numbers::pi * (j + u) / R : 0.0;
      const double c = std::cos(a), sn = std::sin(a);
      auto rot = [&](const Vec3& v) { return Vec3(c * v.x() - sn * v.y(), sn * v.x() + c * v.y(), v.z()); };
      const Vec3 i = rot(s.wi[k]), wo = rot(s.wo[k]);
      auto mirror = [](const Vec3& v) { return Vec3(v.x(), -v.y(), v.z()); };
      out.push(i, wo, s.value[k], w);
      if (sym.reciprocal) out.push(wo, i, s.value[k], w);
      if (sym.bilateral) {
        out.push(mirror(i), mirror(wo), s.value[k], w);
        if (sym.reciprocal) out.push(mirror(wo), mirror(i), s.value[k], w);
      }
    }
  }
  out.validate();
  if (info) *info = {R, G, n, out.size()};
  if (sym.any()) {
    OrbitInfo tmp{R, G, n, out.size()};
    out.description += (out.description.empty() ? "" : "; ") + tmp.describe();
  }
  return out;
}

}  // namespace bf
