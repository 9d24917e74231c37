// Lambert: f = kd / pi (constant), the simplest catalogue model.
#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "brdfs/models_internal.h"

namespace bf {

void LambertParams::validate() const {
  detail::require_nonneg("lambert", "kd", kd);
}

Lambert::Lambert(const LambertParams& p) : p_(p) {
  p_.validate();
}

Rgb Lambert::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  return p_.kd / M_PI;
}

std::string Lambert::to_string() const {
  return "lambert(kd=" + detail::fmt(p_.kd) + ")";
}

void register_lambert(Catalogue& cat) {
  const LambertParams def;
  cat.add_model({"lambert",
                 "f = kd / pi. Energy conserving for kd <= 1 (albedo = kd).",
                 {{"kd", detail::fmt(def.kd), "diffuse albedo, r/g/b or one number, >= 0"}},
                 [](const ParamDict& d) -> BrdfPtr {
                   LambertParams p;
                   p.kd = d.get_rgb("kd", p.kd);
                   return detail::make_checked<Lambert>(d, p);
                 }});
}

}  // namespace bf
