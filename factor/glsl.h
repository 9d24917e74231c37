// Generated GLSL that evaluates a HomomorphicFactorization on the GPU from its
// exported textures (docs/design.md §5 "Factor export").
//
// The generated code defines
//   uniform sampler2D brdf_factor_texK;            one per term K
//   vec3 brdf_factor_eval(vec3 wi, vec3 wo);       RGB in 1/sr, no cosine
// plus helpers prefixed brdf_factor_. It has no #version line so it can be
// pasted or included into a shader; it needs GLSL 3.30 (#version 330 core) or
// later. wi, wo: unit vectors in the local frame of docs/design.md §2 (n = +z,
// t = +x), wi towards the light, wo towards the viewer; 0 below the horizon.
//
// Per term it computes the parabolic point x of (wi, wo) in the term's
// parameterization (halfdiff with the same frame r = normalize(t - (t.h) h),
// fallback t = +y, and the same wi ~ -wo special case as brdfs/directions.cpp),
// the texel coordinates s = clamp(M x + (res-1)/2, 0, res-1), and the lookup
// at uv = (s + 0.5) / res. With the texture uploaded as GL_RGB32F, scanline 0
// first, GL_LINEAR filtering (no mipmaps) and GL_CLAMP_TO_EDGE, the hardware
// bilinear filter at that uv is exactly our bilinear() up to the GPU's filter
// weight precision (often 8 fractional bits). Defining
// BRDF_FACTOR_EXACT_BILINEAR before the code replaces it with four texelFetch
// calls mixed in float. Reciprocal terms read the same texture a second time
// through the conjugate projection. f = A * exp(sum) [- eps*A], max 0.
#pragma once

#include <string>
#include <vector>

#include "factor/homomorphic.h"

namespace bf {

// GLSL source for `f`. texture_files[K] names term K's EXR in the comments
// (one per term, or empty for none); origin (e.g. the sidecar's file name) is
// quoted in the header comment. Throws std::invalid_argument if a constant is
// not finite or texture_files has the wrong size.
std::string generate_glsl(const HomomorphicFactorization& f,
                          const std::vector<std::string>& texture_files,
                          const std::string& origin);

// Name of term K's sampler uniform: "brdf_factor_tex" + K.
std::string glsl_sampler_name(size_t term);

}  // namespace bf
