// Normalized Blinn-Phong: a diffuse term plus a cos^n lobe about the half vector.
#include <cmath>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "brdfs/models_internal.h"

namespace bf {

namespace {
const std::vector<std::string> kNormalizations = {"energy", "ngan"};
}

void BlinnPhongParams::validate() const {
  detail::require_nonneg("blinn-phong", "kd", kd);
  detail::require_nonneg("blinn-phong", "ks", ks);
  detail::require_nonneg("blinn-phong", "n", n);
}

BlinnPhong::BlinnPhong(const BlinnPhongParams& p) : p_(p) {
  p_.validate();
  norm_ = p_.normalization == BlinnPhongParams::Normalization::Energy ? (p_.n + 8.0) / (8.0 * M_PI)
                                                                      : (p_.n + 2.0) / (2.0 * M_PI);
}

Rgb BlinnPhong::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  const Vec3 h = (wi + wo).normalized();
  const double lobe = norm_ * std::pow(std::min(h.z(), 1.0), p_.n);
  return p_.kd / M_PI + p_.ks * lobe;
}

std::string BlinnPhong::to_string() const {
  return "blinn-phong(kd=" + detail::fmt(p_.kd) + ", ks=" + detail::fmt(p_.ks) +
         ", n=" + detail::fmt(p_.n) +
         ", normalization=" + kNormalizations[static_cast<int>(p_.normalization)] + ")";
}

void register_blinn_phong(Catalogue& cat) {
  const BlinnPhongParams def;
  cat.add_model(
      {"blinn-phong",
       "f = kd/pi + ks N cos^n(theta_h), h = normalize(wi + wo); N = (n+8)/(8 pi) "
       "(normalization=energy, Real-Time Rendering: lobe albedo <= 1.07 ks) or (n+2)/(2 pi) "
       "(normalization=ngan, as fitted by Ngan et al. 2005; lobe albedo ~ 4 ks). "
       "Source: Blinn 1977.",
       {{"kd", detail::fmt(def.kd), "diffuse albedo, r/g/b or one number, >= 0"},
        {"ks", detail::fmt(def.ks), "specular scale, r/g/b or one number, >= 0"},
        {"n", detail::fmt(def.n), "exponent, >= 0"},
        {"normalization", "energy", "energy | ngan (see above)"}},
       [](const ParamDict& d) -> BrdfPtr {
         BlinnPhongParams p;
         p.kd = d.get_rgb("kd", p.kd);
         p.ks = d.get_rgb("ks", p.ks);
         p.n = d.get_scalar("n", p.n);
         p.normalization = static_cast<BlinnPhongParams::Normalization>(
             detail::parse_choice(d, "blinn-phong", "normalization", 0, kNormalizations));
         return detail::make_checked<BlinnPhong>(d, p);
       }});
}

}  // namespace bf
