// Runs generated GLSL (a file defining brdf_factor_eval) on Mesa's llvmpipe
// through bf_glsl_run (tests/glsl/glsl_run.cpp, built with the tests) at the
// given direction pairs, with `samplers` bound as name=texture file, and
// compares with the CPU reference `eval` at the same pairs. Returns the worst
// |GLSL - eval| relative to max(|eval|, 1e-3 of the peak |eval| over the pairs)
// (float32 arithmetic: where eval is tiny, its absolute error is what the
// picture sees). Fails the calling test (REQUIRE) when the runner is missing,
// exits non-zero, returns too few or non-finite values, or eval is zero at
// every pair. Uses dir for its files (dirs.txt, out.txt, run.log).
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "brdfs/brdf.h"
#include "test_common.h"

namespace bf_test {

template <class Eval>
double glsl_run_error(const std::string& glsl_file, const std::vector<std::pair<bf::Vec3, bf::Vec3>>& pairs,
                      const std::vector<std::pair<std::string, std::string>>& samplers, Eval eval,
                      const std::filesystem::path& dir) {
  {
    std::ofstream d(dir / "dirs.txt");
    d.precision(17);
    for (const auto& [wi, wo] : pairs)
      d << wi.x() << " " << wi.y() << " " << wi.z() << " " << wo.x() << " " << wo.y() << " " << wo.z() << "\n";
  }
  const std::filesystem::path runner = std::filesystem::read_symlink("/proc/self/exe").parent_path() / "bf_glsl_run";
  INFO("GLSL runner " << runner.string() << " (built with the tests; needs Mesa's EGL: scripts/install-deps.sh)");
  REQUIRE(std::filesystem::exists(runner));
  std::string cmd = runner.string() + " " + glsl_file + " " + (dir / "dirs.txt").string() + " " +
                    (dir / "out.txt").string();
  for (const auto& [sampler, file] : samplers) cmd += " " + sampler + "=" + file;
  cmd += " > " + (dir / "run.log").string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  INFO(slurp((dir / "run.log").string()));
  REQUIRE(rc == 0);
  std::vector<bf::Rgb> cpu;
  double peak = 0.0;
  for (const auto& [wi, wo] : pairs) {
    cpu.push_back(eval(wi, wo));
    peak = std::max(peak, cpu.back().abs().maxCoeff());
  }
  REQUIRE(peak > 0.0);
  std::ifstream out(dir / "out.txt");
  double worst = 0.0;
  for (const bf::Rgb& c : cpu) {
    bf::Rgb g;
    REQUIRE(out >> g[0] >> g[1] >> g[2]);
    REQUIRE(g.isFinite().all());
    for (int ch = 0; ch < 3; ++ch)
      worst = std::max(worst, std::abs(g[ch] - c[ch]) / std::max(std::abs(c[ch]), 1e-3 * peak));
  }
  return worst;
}

}  // namespace bf_test
