// GLSL of the catalogue's analytic models (docs/design.md §5.9): the export of
// a model fit (method "model-fit", runs/<id>/model.glsl beside model.json) and
// what report.html's viewer renders for it.
//
// vec3 brdf_factor_eval(vec3 wi, vec3 wo): the model's formula (brdfs/models.h)
// with its parameters as constants, for the same targets as the other exports
// (OpenGL 3.3 core / 4.5, OpenGL ES 3.0, Vulkan; factor/glsl_target.h). No
// textures. Constants that depend only on parameters (kd / pi, the lobe
// normalizations, 1 / max|C| of a Lafortune lobe) are computed in double and
// written to 9 significant digits, so they round to the float nearest the
// CPU's value. The formulas are rewritten where float32 would lose digits
// that double does not:
//  - cos^2 theta_h = s.z^2 / |s|^2 and tan^2 theta_h = (s.x^2 + s.y^2) / s.z^2
//    from s = wi + wo (not 1 - cos^2 theta_h: cancellation near the highlight);
//  - Blinn-Phong's cos^n theta_h = exp(-n/2 log(1 + tan^2 theta_h)), and
//    Ashikhmin-Shirley's h.z^((nu h.x^2 + nv h.y^2) / (1 - h.z^2)) =
//    exp(-(nu s.x^2 + nv s.y^2) / (2 (s.x^2 + s.y^2)) log(1 + tan^2 theta_h))
//    (1 at s.x = s.y = 0), with log(1 + x) by its series below x = 0.1;
//  - cos theta_d = min(|s| / 2, 1).
// Values beyond float32's range (a lobe of exponent n > ~88 ln(max|C|), a
// Beckmann m < 1e-19) are not representable in the shader: the generator
// refuses parameters that are not finite floats, the rest is float arithmetic.
#pragma once

#include <string>

#include "brdfs/brdf.h"

namespace bf {

// True for the models generate_model_glsl handles: lambert, blinn-phong,
// cook-torrance (schlick and dielectric Fresnel), ward (all variants),
// ashikhmin-shirley (both diffuse terms), lafortune (any lobes, both
// normalizations).
bool has_model_glsl(const Brdf& b);

// The GLSL of such a model; origin (e.g. the run id) goes into the header
// comment. Throws std::invalid_argument for another BRDF or a parameter that
// is not a finite float32, naming it.
std::string generate_model_glsl(const Brdf& b, const std::string& origin = "");

}  // namespace bf
