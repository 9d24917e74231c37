// Lambert: f = kd / pi (constant), the simplest catalogue model.
#include <sstream>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"

namespace bf {

Lambert::Lambert(const LambertParams& p) : p_(p) {
  if ((p.kd < 0.0).any() || !p.kd.isFinite().all())
    throw std::invalid_argument("lambert: kd must be finite and >= 0");
}

Rgb Lambert::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  return p_.kd / M_PI;
}

std::string Lambert::to_string() const {
  std::ostringstream os;
  os << "lambert(kd=" << p_.kd.transpose() << ")";
  return os.str();
}

void register_lambert(Catalogue& cat) {
  cat.add_model({"lambert",
                 "f = kd / pi. Energy conserving for kd <= 1 (albedo = kd).",
                 {{"kd", "0.5", "diffuse albedo, r/g/b or one number, >= 0"}},
                 [](const ParamDict& d) -> BrdfPtr {
                   LambertParams p;
                   p.kd = d.get_rgb("kd", p.kd);
                   return std::make_shared<Lambert>(p);
                 }});
}

}  // namespace bf
