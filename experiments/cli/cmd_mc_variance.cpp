// Subcommand `mc-variance`: the Monte Carlo renderer's check of importance
// sampling (experiments/report/mc_render.h). Renders the SH-lit sphere with
// each sampler, prints per row the integrand, the sampler, the pixel variance
// at --spp, its ratio to cosine sampling of the same integrand, and the RMSE
// of the Monte Carlo image against the deterministic render; with --noise-csv
// also the RMSE at spp = 4, 16, ..., 4 --spp (the report's noise plot).
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "experiments/cli/commands.h"
#include "experiments/report/mc_render.h"
#include "factor/lighting.h"

namespace bf {

namespace {

double image_rmse(const SphereRender& a, const SphereRender& b) { return shade_rmse(a, b); }

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

}  // namespace

void add_cmd_mc_variance(CLI::App& app) {
  auto* cmd = app.add_subcommand("mc-variance",
                                 "Monte Carlo render of the SH-lit sphere per sampler: variance table (and noise CSV)");
  struct Args {
    std::string brdf, approx, env, noise_csv;
    bool mis = false;
    int spp = 64, size = 48, order = 8, view_phi_bins = 0;
    double eps = 1e-3;
    unsigned long long seed = 1;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--brdf", a->brdf, "the original: catalogue name[:k=v,...] or measured file")->required();
  cmd->add_option("--approx", a->approx, "an approximation to compare (e.g. runs/<id>/factors.json)");
  cmd->add_option("--environment", a->env, "lat-long map (.exr/.hdr); default: the default scene's point light, "
                                           "band-limited to --order");
  cmd->add_option("--order", a->order, "SH order of the band-limited point light (no --environment)")
      ->capture_default_str();
  cmd->add_option("--environment-eps", a->eps, "band limit of the map: 1 - eps of its energy")->capture_default_str();
  cmd->add_option("--spp", a->spp, "samples per pixel of the variance column")->capture_default_str();
  cmd->add_option("--size", a->size, "pixels per edge")->capture_default_str();
  cmd->add_option("--seed", a->seed, "seed")->check(non_negative_integer())->capture_default_str();
  cmd->add_option("--view-phi-bins", a->view_phi_bins,
                  "view azimuth bins of the tabulated sampler (0: 1 for an isotropic BRDF, else 16; "
                  "1 for a factorization of an isotropic BRDF, as run does)")
      ->capture_default_str();
  cmd->add_option("--noise-csv", a->noise_csv, "write integrand,sampler,spp,rmse rows here");
  cmd->add_flag("--mis", a->mis,
                "also each sampler combined with sampling the light (one-sample MIS, balance heuristic, "
                "half the samples each): rows <sampler>+light, vs_cosine against cosine+light");
  cmd->callback([a] {
    if (a->spp < 2) throw std::invalid_argument("mc-variance: --spp: expected >= 2, found " + std::to_string(a->spp));
    if (a->size < 8 || a->size > 1024)
      throw std::invalid_argument("mc-variance: --size: expected 8..1024, found " + std::to_string(a->size));
    if (a->view_phi_bins < 0 || a->view_phi_bins > 256)
      throw std::invalid_argument("mc-variance: --view-phi-bins: expected 0..256, found " +
                                  std::to_string(a->view_phi_bins));
    if (a->order < 0 || a->order > 60)
      throw std::invalid_argument("mc-variance: --order: expected 0..60, found " + std::to_string(a->order));
    SceneSettings scene;
    scene.size = a->size;
    if (!a->env.empty()) {
      const LatLongMap map = read_latlong(a->env);
      scene.lighting = std::make_shared<const ShLighting>(
          environment_lighting(map, a->eps, std::min(60, (map.height - 1) / 2)));
    } else {
      scene.lighting = std::make_shared<const ShLighting>(
          directional_lighting(scene.light, Rgb::Constant(scene.intensity / scene.light.squaredNorm()), a->order));
    }
    const Catalogue& cat = Catalogue::global();
    struct Integrand {
      std::string name;
      BrdfPtr f;
    };
    std::vector<Integrand> integrands{{"original", cat.make(a->brdf)}};
    if (!a->approx.empty()) integrands.push_back({"approx", cat.make(a->approx, "--approx")});
    std::ofstream noise;
    if (!a->noise_csv.empty()) {
      noise.open(a->noise_csv);
      if (!noise) throw std::runtime_error(a->noise_csv + ": cannot write the noise CSV");
      noise << "integrand,sampler,spp,rmse\n";
    }
    std::unique_ptr<const LightSampler> light;
    if (a->mis) light = std::make_unique<const LightSampler>(*scene.lighting);
    std::printf("%-9s %-16s %8s %12s %10s %12s\n", "integrand", "sampler", "spp", "variance", "vs_cosine",
                "image_rmse");
    for (const Integrand& in : integrands) {
      const SphereRender det = render_sphere(*in.f, scene);
      std::vector<std::pair<std::string, std::shared_ptr<const BrdfSampler>>> samplers{{"cosine", cosine_sampler()}};
      SamplerOptions tab;
      tab.method = "tabulated";
      tab.view_phi_bins = a->view_phi_bins;
      samplers.push_back({"tabulated", make_sampler(*in.f, tab)});
      // The analytic model's own sampler (Beckmann) for the original, and for
      // the approximation of it too (the same integrand compared with three samplers).
      if (dynamic_cast<const CookTorrance*>(integrands[0].f.get()))
        samplers.push_back({"model", make_sampler(*integrands[0].f)});
      for (int pass = 0; pass < (light ? 2 : 1); ++pass) {
        const LightSampler* ls = pass == 1 ? light.get() : nullptr;
        const std::string suffix = ls ? "+light" : "";
        double cos_var = 0;
        for (const auto& [name, s] : samplers) {
          const McRender r = render_sphere_mc(*in.f, *s, scene, a->spp, a->seed, ls);
          const double v = r.pixel_variance();
          if (name == "cosine") cos_var = v;
          std::printf("%-9s %-16s %8d %12s %10s %12s\n", in.name.c_str(), (name + suffix).c_str(), a->spp,
                      num(v).c_str(), cos_var > 0 ? num(v / cos_var).c_str() : "-",
                      num(image_rmse(det, r.image)).c_str());
          if (noise.is_open())
            for (int spp = 4; spp <= 4 * a->spp; spp *= 4)
              noise << in.name << "," << name << suffix << "," << spp << ","
                    << image_rmse(det, render_sphere_mc(*in.f, *s, scene, spp, a->seed + 1, ls).image) << "\n";
        }
      }
    }
  });
}

}  // namespace bf
