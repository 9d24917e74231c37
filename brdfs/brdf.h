// The BRDF interface every analytic and measured model implements, and the
// frame conventions they all share.
//
// Conventions (docs/design.md §2), stated once here:
//  - Local shading frame: normal n = +z, tangent t = +x, bitangent = +y.
//  - wi points towards the light, wo towards the viewer, both away from the
//    surface, both unit length.
//  - eval(wi, wo) is the BRDF in 1/sr, linear RGB, WITHOUT the cosine factor.
//  - eval returns 0 when wi.z <= 0 or wo.z <= 0 (below the horizon).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <string>

namespace bf {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using Rgb = Eigen::Array3d;  // linear RGB, one double per channel

class Brdf {
 public:
  virtual ~Brdf() = default;
  // BRDF value in 1/sr (no cosine); 0 below the horizon. wi, wo: unit vectors
  // in the local frame.
  virtual Rgb eval(const Vec3& wi, const Vec3& wo) const = 0;
  // Short catalogue name, e.g. "lafortune" or "astm".
  virtual std::string name() const = 0;
  // Name plus every parameter, e.g. "ward(kd=..., rho_s=..., ax=0.1, ay=0.1)".
  virtual std::string to_string() const = 0;
  // Whether f(wi, wo) == f(wo, wi) holds for this model and these parameters.
  virtual bool reciprocal() const { return true; }
  // Whether f is invariant under a common rotation of wi and wo about n.
  virtual bool isotropic() const { return true; }
  // Whether f is invariant under the mirror y -> -y of both wi and wo
  // (brdfs/symmetry.h). False unless a model's formula gives it.
  virtual bool bilateral() const { return false; }
  // Whether eval is the BRDF over the whole domain (a truth to validate
  // against). Analytic models and MERL tables: true. An interpolant of
  // scattered samples: only when the symmetries it assumes are declared by its
  // data; else false with the reason in *why.
  virtual bool whole_domain(std::string* why = nullptr) const {
    (void)why;
    return true;
  }
  // Whether eval(wi, wo) is backed by the BRDF's data. False only where a
  // measured table has no value there (eval then returns its fill value, 0):
  // a comparison against this BRDF as the truth skips such pairs.
  virtual bool defined_at(const Vec3& wi, const Vec3& wo) const {
    (void)wi;
    (void)wo;
    return true;
  }
};

using BrdfPtr = std::shared_ptr<const Brdf>;

}  // namespace bf
