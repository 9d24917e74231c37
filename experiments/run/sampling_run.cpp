// See sampling_run.h.
#include "experiments/run/sampling_run.h"

#include <chrono>

#include "experiments/common/cli_util.h"
#include "experiments/report/mc_render.h"
#include "experiments/report/render.h"
#include "factor/sampling.h"
#include "factor/sampling_export.h"

namespace bf {

namespace {

// The report's noise against samples: the run's result rendered by Monte
// Carlo (a 16-pixel sphere of the scene; a point light band-limited to order
// 8 when the scene has no SH lighting) with cosine sampling and with its own
// sampler, image RMSE against the deterministic render at 4, 16 and 64 spp.
nlohmann::json sampling_noise(const Brdf& result, const BrdfSampler& own, const SceneSettings& scene) {
  SceneSettings small = scene;
  small.size = 16;
  if (!small.lighting)
    small.lighting = std::make_shared<const ShLighting>(
        directional_lighting(scene.light, Rgb::Constant(scene.intensity / scene.light.squaredNorm()), 8));
  const SphereRender det = render_sphere(result, small);
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& [name, s] : {std::pair<const char*, const BrdfSampler*>{"cosine", cosine_sampler().get()},
                                {"tabulated", &own}})
    for (int spp : {4, 16, 64})
      rows.push_back({{"sampler", name},
                      {"spp", spp},
                      {"rmse", shade_rmse(det, render_sphere_mc(result, *s, small, spp, 1).image)}});
  return rows;
}

}  // namespace

void run_sampling(const Brdf& result, bool fitted_isotropic, const SceneSettings& scene, bool export_files,
                  const std::filesystem::path& run_dir, Row& row, nlohmann::json& record) {
  SamplerOptions o;
  o.method = "tabulated";
  if (fitted_isotropic) o.view_phi_bins = 1;
  const auto t0 = std::chrono::steady_clock::now();
  const auto s = make_sampler(result, o);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row["sampler_storage"] = std::to_string(s->storage_floats());
  row["sampler_build_s"] = format_number(seconds);
  const SamplerTable& t = *sampler_table(*s);
  nlohmann::json entry = sampling_entry(t, "sampling.exr", "sampling.glsl");
  entry.erase("file"), entry.erase("glsl");  // nothing written without export
  if (export_files) {
    entry = write_sampling_export(*s, run_dir.string());
    write_file_atomic((run_dir / "sampling.json").string(),
                      [&](std::ostream& out) { out << entry.dump(2) << "\n"; });
  }
  entry["build_seconds"] = seconds;
  entry["noise"] = sampling_noise(result, *s, scene);
  record["sampler"] = entry;
}

}  // namespace bf
