// The analytic models of the catalogue: one small final class per model with a
// parameter struct, formula and source documented at the declaration.
#pragma once

#include "brdfs/brdf.h"

namespace bf {

class Catalogue;

// Lambert: f = kd / pi.
struct LambertParams {
  Rgb kd = Rgb::Constant(0.5);  // diffuse albedo per channel, >= 0
};
class Lambert final : public Brdf {
 public:
  explicit Lambert(const LambertParams& p);
  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  std::string name() const override { return "lambert"; }
  std::string to_string() const override;
  const LambertParams& params() const { return p_; }

 private:
  LambertParams p_;
};

void register_lambert(Catalogue& cat);

}  // namespace bf
