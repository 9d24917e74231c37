// Ashikhmin-Shirley anisotropic Phong: Schlick-Fresnel specular lobe plus the
// paper's coupled diffuse term (or a Lambertian one, for Ngan's fits).
#include <algorithm>
#include <cmath>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "brdfs/models_internal.h"

namespace bf {

namespace {
const std::vector<std::string> kDiffuse = {"ashikhmin-shirley", "lambert"};
const char* kModel = "ashikhmin-shirley";

double pow5(double x) {
  const double x2 = x * x;
  return x2 * x2 * x;
}
}  // namespace

void AshikhminShirleyParams::validate() const {
  detail::require_nonneg(kModel, "rd", rd);
  detail::require(rs.isFinite().all() && (rs >= 0.0).all() && (rs <= 1.0).all(), kModel, "rs",
                  detail::fmt(rs), "in [0, 1]");
  detail::require_nonneg(kModel, "nu", nu);
  detail::require_nonneg(kModel, "nv", nv);
  detail::require_nonneg(kModel, "ks", ks);
}

AshikhminShirley::AshikhminShirley(const AshikhminShirleyParams& p) : p_(p) {
  p_.validate();
}

Rgb AshikhminShirley::eval(const Vec3& wi, const Vec3& wo) const {
  const double ci = wi.z(), co = wo.z();
  if (ci <= 0.0 || co <= 0.0) return Rgb::Zero();
  const Vec3 sum = wi + wo;
  const double len = sum.norm();
  const Vec3 h = sum / len;
  const double cd = 0.5 * len;  // wi.h = wo.h, symmetric in wi, wo
  // h.z^((nu hx^2 + nv hy^2) / (1 - h.z^2)) = exp((nu hx^2 + nv hy^2) / 2 * log(1 - s2) / s2)
  // with s2 = hx^2 + hy^2 = 1 - h.z^2, evaluated without cancellation; limit 1 at h = n.
  const double s2 = h.x() * h.x() + h.y() * h.y();
  const double log_ratio = s2 > 1e-300 ? std::log1p(-std::min(s2, 1.0)) / s2 : -1.0;
  const double lobe = std::exp(0.5 * (p_.nu * h.x() * h.x() + p_.nv * h.y() * h.y()) * log_ratio);
  const double norm = std::sqrt((p_.nu + 1.0) * (p_.nv + 1.0)) / (8.0 * M_PI);
  const Rgb spec = p_.ks * fresnel_schlick(p_.rs, cd) * (norm * lobe / (cd * std::max(ci, co)));
  Rgb diff;
  if (p_.diffuse == AshikhminShirleyParams::Diffuse::AshikhminShirley)
    diff = 28.0 / (23.0 * M_PI) * p_.rd * (1.0 - p_.rs) * (1.0 - pow5(1.0 - 0.5 * ci)) *
           (1.0 - pow5(1.0 - 0.5 * co));
  else
    diff = p_.rd / M_PI;
  return diff + spec;
}

std::string AshikhminShirley::to_string() const {
  std::string s = "ashikhmin-shirley(rd=" + detail::fmt(p_.rd) + ", rs=" + detail::fmt(p_.rs) +
                  ", nu=" + detail::fmt(p_.nu) + ", nv=" + detail::fmt(p_.nv);
  if ((p_.ks != 1.0).any()) s += ", ks=" + detail::fmt(p_.ks);
  return s + ", diffuse=" + kDiffuse[static_cast<int>(p_.diffuse)] + ")";
}

void register_ashikhmin_shirley(Catalogue& cat) {
  const AshikhminShirleyParams def;
  cat.add_model(
      {"ashikhmin-shirley",
       "f = f_d + ks sqrt((nu+1)(nv+1))/(8 pi) h.z^((nu h.x^2 + nv h.y^2)/(1 - h.z^2)) F / "
       "(cd max(ci, co)), F = rs + (1-rs)(1-cd)^5; f_d = 28 rd/(23 pi) (1-rs) "
       "(1-(1-ci/2)^5)(1-(1-co/2)^5) (diffuse=ashikhmin-shirley) or rd/pi (diffuse=lambert). "
       "Source: Ashikhmin and Shirley 2000.",
       {{"rd", detail::fmt(def.rd), "diffuse reflectance, r/g/b or one number, >= 0"},
        {"rs", detail::fmt(def.rs), "specular reflectance at normal incidence, in [0, 1]"},
        {"nu", detail::fmt(def.nu), "exponent along the tangent +x, >= 0"},
        {"nv", detail::fmt(def.nv), "exponent along +y, >= 0 (nu = nv: isotropic)"},
        {"ks", detail::fmt(def.ks), "extra specular scale, >= 0 (1 in the paper)"},
        {"diffuse", "ashikhmin-shirley", "ashikhmin-shirley | lambert"}},
       [](const ParamDict& d) -> BrdfPtr {
         AshikhminShirleyParams p;
         p.rd = d.get_rgb("rd", p.rd);
         p.rs = d.get_rgb("rs", p.rs);
         p.nu = d.get_scalar("nu", p.nu);
         p.nv = d.get_scalar("nv", p.nv);
         p.ks = d.get_rgb("ks", p.ks);
         p.diffuse = static_cast<AshikhminShirleyParams::Diffuse>(
             detail::parse_choice(d, kModel, "diffuse", 0, kDiffuse));
         return detail::make_checked<AshikhminShirley>(d, p);
       }});
}

}  // namespace bf
