// `[[method]] sampler = true`: the importance sampler of a run's result
// (factor/sampling.h, default SamplerOptions), its columns sampler_storage
// (floats a renderer holds to sample) and sampler_build_s (seconds to build
// it), its run.json entry "sampler", and with export on its files in the run
// folder: sampling.exr (the table), sampling.glsl (brdf_factor_sample,
// brdf_factor_pdf) and sampling.json (the sidecar entry; docs/design.md,
// "Importance sampling"). The exported sampler is always the table (the
// GLSL reads it), also where make_sampler would pick a model's own sampler.
// fitted_isotropic: the BRDF the result approximates passed the isotropy test
// (factor/isotropy.h); the table then has one view azimuth bin (for a result
// that does not say it is isotropic, the mean of f cos over view azimuths:
// factor/sampling.h), else make_sampler's default. The run.json entry also
// holds "noise": rows {sampler, spp, rmse} of a small Monte Carlo render of
// the scene with cosine sampling and with this sampler (report.html plots them).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>

#include "brdfs/brdf.h"
#include "experiments/plan/plan.h"
#include "experiments/report/outputs.h"

namespace bf {

void run_sampling(const Brdf& result, bool fitted_isotropic, const SceneSettings& scene, bool export_files,
                  const std::filesystem::path& run_dir, Row& row, nlohmann::json& record);

}  // namespace bf
