// Every registered method kind can be importance sampled: its exported
// factorization (reloaded as the renderer would) gets a sampler
// (factor/sampling.h) that passes the chi-squared test against its own pdf at
// theta_o = 0, 45 and 80 degrees (p > 0.01 after Sidak's correction over the
// three views), on bluepaint, Cook-Torrance m = 0.2 and the Cornell paint
// krylon-blue.
#include <cmath>

#include "brdfs/catalogue.h"
#include "experiments/methods/method_kind.h"
#include "experiments_helpers.h"
#include "factor/sampling.h"
#include "factor/sampling_chi2.h"

using namespace bf;
using namespace bf_test;

namespace {

void check_every_kind(const std::string& brdf_section, size_t n) {
  REQUIRE(method_kinds().size() >= 7);
  register_loaders();
  for (const auto& kind : method_kinds()) {
    INFO(kind->name() << " on " << brdf_section);
    ScratchDir tmp;
    const std::string cfg = write_text(tmp / "cfg.toml", R"([experiment]
name = "t"
plots = false
render = false

[[brdf]]
)" + brdf_section + R"(

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = ")" + kind->name() + "\"\n" + kind->example());
    const RunSummary s = run_quiet(cfg, tmp / "out");
    REQUIRE(s.failed == 0);
    const auto rows = read_results_csv(tmp / "out/results.csv");
    REQUIRE(rows.size() == 1);
    const fs::path run = fs::path(tmp / "out/runs") / rows[0].at("run_id");
    const bool model = fs::exists(run / "model.json");
    const BrdfPtr f = Catalogue::global().make((run / (model ? "model.json" : "factors.json")).string());
    SamplerOptions so;
    so.view_bins = 8, so.theta_bins = 16, so.phi_bins = 32, so.cell_samples = 1;
    const auto sampler = make_sampler(*f, so);
    double pmin = 1;
    for (double t : {0.0, 45.0, 80.0}) {
      const double th = t * M_PI / 180, ph = 0.7;
      const Vec3 wo(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      Chi2Options o;
      o.samples = n;
      const Chi2Result r = chi2_test(*sampler, wo, o);
      INFO(sampler->method() << " theta_o " << t << ": chi2 " << r.chi2 << " dof " << r.dof << " p " << r.p
                             << " " << r.problem);
      CHECK(r.problem.empty());
      pmin = std::min(pmin, r.p);
    }
    INFO("smallest p " << pmin);
    CHECK(sidak(pmin, 3) > 0.01);
  }
}

}  // namespace

TEST_CASE("sampling: every kind's sampler passes chi2 on bluepaint") {
  check_every_kind("preset = \"bluepaint\"", 10000);
}

TEST_CASE("sampling: every kind's sampler passes chi2 on Cook-Torrance and a Cornell paint [slow]", "[slow]") {
  check_every_kind("preset = \"bluepaint\"", 1000000);
  check_every_kind("model = \"cook-torrance\"\nkd = 0.1\nks = 0.9\nm = 0.2\nf0 = 0.1", 1000000);
  check_every_kind("model = \"krylon-blue\"", 1000000);
}
