// The [scene] table of an experiment config (see config.h: SceneSettings, and
// docs/experiments.md): the sphere render's light, size, SH lighting from an
// environment map or a band-limited point light, and whether runs get shade_rmse.
#include <algorithm>
#include <cmath>
#include <toml++/toml.h>

#include "experiments/common/cli_util.h"
#include "experiments/config/config.h"
#include "experiments/plan/config_reader.h"
#include "factor/lighting.h"

namespace bf {

SceneSettings read_scene(const toml::table* t, Ctx& ctx) {
  SceneSettings s;
  if (!t) return s;
  s.named = true;
  const Combo c = plain_combo(*t);
  Reader r(ctx, c, "scene", ctx.where(*t));
  s.shade = r.boolean("shade_rmse", true);
  if (const toml::node* n = r.take("light")) {
    auto a = n->as_array();
    bool ok = a && a->size() == 3;
    Vec3 p = Vec3::Zero();
    for (size_t i = 0; ok && i < 3; ++i) {
      const auto& e = *a->get(i);
      if (auto x = e.as_integer()) p[i] = static_cast<double>(x->get());
      else if (auto f = e.as_floating_point()) p[i] = f->get();
      else ok = false;
      if (!std::isfinite(p[i])) ok = false;
    }
    if (!ok) r.fail("light", "expected a position [x, y, z] of three finite numbers, " + found(*n));
    else if (p.norm() <= 1.0) r.fail("light", "expected a position outside the unit sphere (|p| > 1), found |p| = " + fmt_num(p.norm()));
    else s.light = p;
  }
  s.intensity = r.number("intensity", s.intensity, 0.0, kInf, true);
  s.size = static_cast<int>(r.integer("size", s.size, 16, 1024));
  // SH lighting (factor/lighting.h): an environment map with a measured band
  // limit, or an explicit order (alone: the point light band-limited to it).
  const bool has_env = r.has("environment"), has_order = r.has("lighting_order");
  const std::string env = r.text("environment", "");
  s.environment_eps = r.number("environment_eps", s.environment_eps, 0.0, 1.0, true);
  s.lighting_order = static_cast<int>(r.integer("lighting_order", -1, 0, 60));
  s.lighting_nodes = static_cast<int>(r.integer("lighting_nodes", 0, 0, 512));
  if (r.has("environment_eps") && (!has_env || has_order))
    r.fail("environment_eps", has_env ? "environment_eps measures the band limit, but lighting_order fixes it: remove one"
                                      : "environment_eps needs environment = \"<lat-long map>\"");
  if (has_env && (r.has("light") || r.has("intensity")))
    r.fail(r.has("light") ? "light" : "intensity",
           "light and intensity describe the point light; with environment the map's radiance lights the sphere");
  if (has_env && !r.failed()) {
    std::vector<std::string> tried;
    s.environment = ctx.resolve(env, &tried);
    if (s.environment.empty()) {
      r.fail("environment", "file not found (looked for " + join(tried, ", ") + ")");
    } else {
      try {
        const LatLongMap map = read_latlong(s.environment);
        const int cap = std::min(60, (map.height - 1) / 2);
        if (has_order) {
          if (s.lighting_order > cap)
            throw std::invalid_argument(s.environment + ": lighting_order " + std::to_string(s.lighting_order) +
                                        " exceeds the order a " + std::to_string(map.width) + "x" +
                                        std::to_string(map.height) + " map resolves exactly (" + std::to_string(cap) + ")");
          ShLighting l = project_latlong(map, s.lighting_order);
          l.band_limit = s.lighting_order;
          s.lighting = std::make_shared<const ShLighting>(std::move(l));
        } else {
          s.lighting = std::make_shared<const ShLighting>(environment_lighting(map, s.environment_eps, cap));
        }
      } catch (const std::exception& e) {
        r.fail("environment", e.what());
      }
    }
  } else if (has_order && !r.failed()) {
    const double d2 = s.light.squaredNorm();
    s.lighting = std::make_shared<const ShLighting>(
        directional_lighting(s.light, Rgb::Constant(s.intensity / d2), s.lighting_order));
  }
  r.finish(config_keys("scene"), "[scene]");
  return s;
}

}  // namespace bf
