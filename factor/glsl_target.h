// What makes generated GLSL compile unchanged for every target a renderer
// uses (docs/design.md §5.7): OpenGL 3.3 core and 4.5, OpenGL ES 3.0 and Vulkan
// (glslangValidator -V, which defines VULKAN). Shared by the homomorphic
// export (factor/glsl.cpp) and the SVD / SH exports (factor/baseline_export.cpp).
#pragma once

#include <string>

namespace bf {

// Lines to put before the first declaration of generated code:
//  - under GL_ES: default precisions highp for float, int and sampler2D
//    (ES fragment shaders have no default float precision);
//  - the macro BRDF_FACTOR_BINDING(n): layout(set = 0, binding = n) under
//    VULKAN (opaque uniforms need a binding there), nothing otherwise. A
//    renderer may #define BRDF_FACTOR_BINDING(n) itself before the code (for
//    another set or a binding offset); the generated code then keeps it.
std::string glsl_target_prelude();

// "BRDF_FACTOR_BINDING(binding) uniform sampler2D name;"
std::string glsl_sampler_decl(const std::string& name, int binding);

// A GLSL float literal that rounds to the same float32 as v (9 significant
// digits), always with a '.' or an exponent. Throws std::invalid_argument
// naming `what` when v is not finite or beyond float32's range.
std::string glsl_float(double v, const std::string& what);

// GLSL helpers shared by the SVD and SH exports: brdf_factor_parabolic(vec3)
// and brdf_factor_halfdiff(vec3 wi, vec3 wo) (the x = (p(h), p(d)) of docs/design.md
// §2.3, grazing branch and t = +y fallback included). The homomorphic export
// has its own copy in factor/glsl.cpp (same text).
const char* glsl_point_helpers();

}  // namespace bf
