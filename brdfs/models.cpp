// Registers every analytic model with the catalogue, and holds the pieces the
// model sources share (Fresnel terms, parameter checks, number formatting).
#include "brdfs/models.h"
#include "brdfs/models_internal.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include "brdfs/catalogue.h"

namespace bf {

void register_analytic_models(Catalogue& cat) {
  register_lambert(cat);
  register_blinn_phong(cat);
  register_cook_torrance(cat);
  register_lafortune(cat);
  register_ward(cat);
  register_ashikhmin_shirley(cat);
  register_separable(cat);
}

Rgb fresnel_schlick(const Rgb& f0, double cd) {
  const double t = std::clamp(1.0 - cd, 0.0, 1.0);
  const double t2 = t * t;
  return f0 + (1.0 - f0) * (t2 * t2 * t);
}

double fresnel_dielectric(double eta, double cd) {
  const double c = std::clamp(cd, 0.0, 1.0);
  const double g2 = eta * eta - 1.0 + c * c;
  if (g2 <= 0.0) return 1.0;  // total internal reflection
  const double g = std::sqrt(g2);
  const double a = (g - c) / (g + c);
  const double b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
  return 0.5 * a * a * (1.0 + b * b);
}

namespace detail {

std::string fmt(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, res.ptr);
}

std::string fmt(const Rgb& v) {
  if (v[0] == v[1] && v[1] == v[2]) return fmt(v[0]);
  return fmt(v[0]) + "/" + fmt(v[1]) + "/" + fmt(v[2]);
}

void require(bool ok, const std::string& model, const std::string& key, const std::string& value,
             const std::string& rule) {
  if (!ok)
    throw std::invalid_argument(model + ": " + key + " = " + value + " is out of range: must be " +
                                rule);
}

void require_nonneg(const std::string& model, const std::string& key, const Rgb& v) {
  require(v.isFinite().all() && (v >= 0.0).all(), model, key, fmt(v), "finite and >= 0");
}

void require_nonneg(const std::string& model, const std::string& key, double v) {
  require(std::isfinite(v) && v >= 0.0, model, key, fmt(v), "finite and >= 0");
}

void require_positive(const std::string& model, const std::string& key, double v) {
  require(std::isfinite(v) && v > 0.0, model, key, fmt(v), "finite and > 0");
}

int parse_choice(const ParamDict& d, const std::string& model, const std::string& key, int def,
                 const std::vector<std::string>& choices) {
  const std::string value = d.get_string(key, choices.at(def));
  std::string all;
  for (size_t i = 0; i < choices.size(); ++i) {
    if (choices[i] == value) return static_cast<int>(i);
    all += (i ? ", " : "") + choices[i];
  }
  throw std::invalid_argument(d.origin() + ": " + model + ": " + key + " = '" + value +
                              "' is not one of " + all);
}

}  // namespace detail
}  // namespace bf
