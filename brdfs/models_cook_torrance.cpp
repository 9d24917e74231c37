// Cook-Torrance: Beckmann microfacet distribution, V-groove masking, Schlick or
// exact dielectric Fresnel, in the Foley, 1982-paper or Ngan normalization.
#include <algorithm>
#include <cmath>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "brdfs/models_internal.h"

namespace bf {

namespace {
const std::vector<std::string> kFresnel = {"schlick", "dielectric"};
const std::vector<std::string> kForms = {"foley", "cook-torrance", "ngan"};
}  // namespace

void CookTorranceParams::validate() const {
  const std::string m_ = "cook-torrance";
  detail::require_nonneg(m_, "kd", kd);
  detail::require_nonneg(m_, "ks", ks);
  detail::require_positive(m_, "m", m);
  detail::require(f0.isFinite().all() && (f0 >= 0.0).all() && (f0 <= 1.0).all(), m_, "f0",
                  detail::fmt(f0), "in [0, 1]");
  detail::require(eta.isFinite().all() && (eta > 0.0).all(), m_, "eta", detail::fmt(eta),
                  "finite and > 0");
}

CookTorrance::CookTorrance(const CookTorranceParams& p) : p_(p) {
  p_.validate();
  switch (p_.form) {
    case CookTorranceParams::Form::Foley:
      inv_k_ = 1.0 / (4.0 * M_PI);
      break;
    case CookTorranceParams::Form::CookTorrance:
      inv_k_ = 1.0 / M_PI;
      break;
    case CookTorranceParams::Form::Ngan:
      inv_k_ = 1.0 / (M_PI * M_PI);
      break;
  }
}

Rgb CookTorrance::eval(const Vec3& wi, const Vec3& wo) const {
  const double ci = wi.z(), co = wo.z();
  if (ci <= 0.0 || co <= 0.0) return Rgb::Zero();
  const Vec3 sum = wi + wo;
  const double len = sum.norm();
  const double ch = std::min(sum.z() / len, 1.0);  // cos theta_h > 0
  const double cd = 0.5 * len;                     // wi.h = wo.h, symmetric in wi, wo
  const double ch2 = ch * ch;
  const double tan2 = std::max(1.0 - ch2, 0.0) / ch2;
  const double m2 = p_.m * p_.m;
  const double d = std::exp(-tan2 / m2) / (m2 * ch2 * ch2);
  const double g = std::min({1.0, 2.0 * ch * co / cd, 2.0 * ch * ci / cd});
  Rgb f;
  if (p_.fresnel == CookTorranceParams::Fresnel::Schlick) {
    f = fresnel_schlick(p_.f0, cd);
  } else {
    for (int c = 0; c < 3; ++c) f[c] = fresnel_dielectric(p_.eta[c], cd);
  }
  return p_.kd / M_PI + p_.ks * f * (d * g * inv_k_ / (ci * co));
}

std::string CookTorrance::to_string() const {
  std::string s = "cook-torrance(kd=" + detail::fmt(p_.kd) + ", ks=" + detail::fmt(p_.ks) +
                  ", m=" + detail::fmt(p_.m) +
                  ", fresnel=" + kFresnel[static_cast<int>(p_.fresnel)];
  s += p_.fresnel == CookTorranceParams::Fresnel::Schlick ? ", f0=" + detail::fmt(p_.f0)
                                                          : ", eta=" + detail::fmt(p_.eta);
  return s + ", form=" + kForms[static_cast<int>(p_.form)] + ")";
}

void register_cook_torrance(Catalogue& cat) {
  const CookTorranceParams def;
  cat.add_model(
      {"cook-torrance",
       "f = kd/pi + ks F G exp(-tan^2(theta_h)/m^2) / (K m^2 cos^4(theta_h) ci co): Beckmann D, "
       "V-groove G = min(1, 2 h.z co/cd, 2 h.z ci/cd), F Schlick(f0) or exact dielectric(eta). "
       "K = 4 pi (form=foley: Foley et al. 1990 §16.7, = unit-normalized Beckmann F D G/(4 ci "
       "co)), "
       "pi (form=cook-torrance: the 1982 paper, 4x foley), pi^2 (form=ngan: bbm's Ngan 2005). "
       "Source: Cook and Torrance 1982.",
       {{"kd", detail::fmt(def.kd), "diffuse albedo, r/g/b or one number, >= 0"},
        {"ks", detail::fmt(def.ks), "specular scale, r/g/b or one number, >= 0"},
        {"m", detail::fmt(def.m), "Beckmann rms slope, > 0"},
        {"fresnel", "schlick", "schlick (uses f0) | dielectric (uses eta)"},
        {"f0", detail::fmt(def.f0), "Schlick reflectance at normal incidence, r/g/b, in [0, 1]"},
        {"eta", detail::fmt(def.eta), "relative index of refraction, r/g/b, > 0"},
        {"form", "foley", "foley | cook-torrance | ngan: normalization K (see above)"}},
       [](const ParamDict& d) -> BrdfPtr {
         CookTorranceParams p;
         p.kd = d.get_rgb("kd", p.kd);
         p.ks = d.get_rgb("ks", p.ks);
         p.m = d.get_scalar("m", p.m);
         p.fresnel = static_cast<CookTorranceParams::Fresnel>(
             detail::parse_choice(d, "cook-torrance", "fresnel", 0, kFresnel));
         if (p.fresnel == CookTorranceParams::Fresnel::Schlick) {
           if (d.has("eta"))
             throw std::invalid_argument(d.origin() +
                                         ": cook-torrance: eta applies only to "
                                         "fresnel=dielectric; with fresnel=schlick give f0");
           p.f0 = d.get_rgb("f0", p.f0);
         } else {
           if (d.has("f0"))
             throw std::invalid_argument(d.origin() +
                                         ": cook-torrance: f0 applies only to "
                                         "fresnel=schlick; with fresnel=dielectric give eta");
           p.eta = d.get_rgb("eta", p.eta);
         }
         p.form = static_cast<CookTorranceParams::Form>(
             detail::parse_choice(d, "cook-torrance", "form", 0, kForms));
         return detail::make_checked<CookTorrance>(d, p);
       }});
}

}  // namespace bf
