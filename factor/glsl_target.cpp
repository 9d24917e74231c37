// See glsl_target.h.
#include "factor/glsl_target.h"

#include <cfloat>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace bf {

std::string glsl_target_prelude() {
  return "// Targets: OpenGL 3.3 core / 4.5, OpenGL ES 3.0 (#version 300 es), Vulkan (VULKAN defined,\n"
         "// e.g. by glslangValidator -V): samplers get layout(set = 0, binding = n) there; define\n"
         "// BRDF_FACTOR_BINDING(n) before this code to choose other sets or bindings.\n"
         "#ifdef GL_ES\n"
         "precision highp float;\n"
         "precision highp int;\n"
         "precision highp sampler2D;\n"
         "#endif\n"
         "#ifndef BRDF_FACTOR_BINDING\n"
         "#ifdef VULKAN\n"
         "#define BRDF_FACTOR_BINDING(n) layout(set = 0, binding = n)\n"
         "#else\n"
         "#define BRDF_FACTOR_BINDING(n)\n"
         "#endif\n"
         "#endif\n";
}

std::string glsl_sampler_decl(const std::string& name, int binding) {
  return "BRDF_FACTOR_BINDING(" + std::to_string(binding) + ") uniform sampler2D " + name + ";";
}

std::string glsl_float(double v, const std::string& what) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  if (!std::isfinite(v) || std::abs(v) > FLT_MAX)
    throw std::invalid_argument("glsl: " + what + " = " + buf + " is not a finite float32 (|value| <= 3.4e38)");
  std::string s = buf;
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

const char* glsl_point_helpers() {
  return R"(// Heidrich-Seidel parabolic map of the upper hemisphere onto the unit disk.
vec2 brdf_factor_parabolic(vec3 w) { return w.xy / (1.0 + w.z); }

// x = (p(h), p(d)) of the halfdiff parameterization (docs/design.md §2.3):
// h = normalize(wi + wo) (n if wi = -wo); frame r = normalize(t - (t.h) h) with
// t = +x, or t = +y when that is shorter than 1e-12; s = h x r;
// d = (wi.r, wi.s, wi.h), except for |wi + wo| < 1 where d.z = |wi + wo| / 2
// and (d.x, d.y) is rescaled to keep |d| = 1. For unit h, t - (t.h) h with
// t = +x is (h.y^2 + h.z^2, -h.x h.y, -h.x h.z): written so, it avoids the
// cancellation in 1 - h.x^2 near h = +-x.
vec4 brdf_factor_halfdiff(vec3 wi, vec3 wo) {
  vec3 sum = wi + wo;
  float n = length(sum);
  vec3 h = n > 0.0 ? sum / n : vec3(0.0, 0.0, 1.0);
  vec3 r = vec3(h.y * h.y + h.z * h.z, -h.x * h.y, -h.x * h.z);
  float rn = length(r);
  if (rn < 1e-12) {
    r = vec3(-h.x * h.y, h.x * h.x + h.z * h.z, -h.y * h.z);
    rn = length(r);
  }
  r /= rn;
  vec3 s = cross(h, r);
  vec2 dt = vec2(dot(wi, r), dot(wi, s));
  float dz = dot(wi, h);
  if (0.5 * n < 0.5) {
    dz = 0.5 * n;
    float tn = length(dt);
    if (tn > 0.0) dt *= sqrt(max(1.0 - dz * dz, 0.0)) / tn;
  }
  return vec4(brdf_factor_parabolic(h), brdf_factor_parabolic(vec3(dt, dz)));
}
)";
}

}  // namespace bf
