// Export of a tabulated sampler (factor/sampling.h) beside the factors: the
// table as a float EXR texture, its entry for the JSON sidecar, and GLSL
// brdf_factor_sample / brdf_factor_pdf that read it. File format:
// docs/design.md, "Importance sampling".
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "factor/image_io.h"
#include "factor/sampling.h"

namespace bf {

// The table as an image: width (max(theta_bins, phi_bins) + 1) * view_phi_bins,
// height (theta_bins + 1) * view_bins, value in R (G = B = 0). View (vt, vp)
// occupies the block at x0 = vp * (max(T, P) + 1), y0 = vt * (T + 1): its row
// CDF (T + 1 values) in row y0, the CDF over phi of theta row r (P + 1
// values) in row y0 + 1 + r. An empty view (cosine sampling only) has an
// all-zero row CDF.
FloatImage sampling_texture(const SamplerTable& t);
// The table read back from such an image and its sidecar entry; throws
// std::invalid_argument naming `what` and the field when they disagree.
SamplerTable sampling_table_from(const FloatImage& img, const nlohmann::json& entry, const std::string& what);
// A sampler drawing from a table (as make_sampler's tabulated one).
std::shared_ptr<const BrdfSampler> tabulated_sampler(SamplerTable t);

// GLSL (for the four targets of factor/glsl_target.h) defining
//   vec4 brdf_factor_sample(vec3 wo, vec2 u): xyz = wi, w = pdf (0: no sample);
//   float brdf_factor_pdf(vec3 wi, vec3 wo);
// from the texture `brdf_factor_sampling` (texelFetch, no filtering), bound
// at BRDF_FACTOR_SAMPLING_BINDING (default 15; define it before the code to
// choose another).
std::string sampling_glsl(const SamplerTable& t);

// The sidecar entry: {"method": "tabulated", "file", "glsl", the table's
// sizes, cosine_fraction, storage_floats}.
nlohmann::json sampling_entry(const SamplerTable& t, const std::string& file, const std::string& glsl_file);

// Writes dir/sampling.exr and dir/sampling.glsl for the table of s and returns
// its sidecar entry. Throws std::invalid_argument when s is not tabulated.
nlohmann::json write_sampling_export(const BrdfSampler& s, const std::string& dir);

}  // namespace bf
