// Every registered method kind can be importance sampled: its exported
// factorization (reloaded as the renderer would) gets a sampler
// (factor/sampling.h) that passes the chi-squared test against its own pdf at
// theta_o = 0, 45 and 80 degrees (p > 0.01 after Sidak's correction over the
// three views), on bluepaint, Cook-Torrance m = 0.2 and the Cornell paint
// krylon-blue.
#include <cmath>
#include <map>

#include "brdfs/catalogue.h"
#include "experiments/methods/method_kind.h"
#include "experiments_helpers.h"
#include "factor/sampling.h"
#include "factor/sampling_chi2.h"
#include "factor/sampling_export.h"

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

TEST_CASE("sampling: every kind's sampler passes chi2 on Cook-Torrance and a Cornell paint", "[slow]") {
  check_every_kind("preset = \"bluepaint\"", 1000000);
  check_every_kind("model = \"cook-torrance\"\nkd = 0.1\nks = 0.9\nm = 0.2\nf0 = 0.1", 1000000);
  check_every_kind("model = \"krylon-blue\"", 1000000);
}

TEST_CASE("sampling: sampler = true builds the sampler and writes its export and columns") {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "cfg.toml", R"([experiment]
name = "t"
plots = false
render = false

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "sh-k"
order = 2
sampler = true

[[method]]
kind = "sh-k"
label = "without"
order = 2
)");
  const RunSummary s = run_quiet(cfg, tmp / "out");
  REQUIRE(s.failed == 0);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 2);
  for (const auto& row : rows) {
    const fs::path run = fs::path(tmp / "out/runs") / row.at("run_id");
    const bool with = row.at("label") != "without";
    INFO(row.at("label"));
    CHECK(fs::exists(run / "sampling.exr") == with);
    CHECK(fs::exists(run / "sampling.glsl") == with);
    CHECK(fs::exists(run / "sampling.json") == with);
    CHECK(row.at("sampler_storage").empty() == !with);
    CHECK(row.at("sampler_build_s").empty() == !with);
    if (!with) continue;
    const nlohmann::json entry = nlohmann::json::parse(slurp((run / "sampling.json").string()));
    CHECK(std::to_string(entry.at("storage_floats").get<size_t>()) == row.at("sampler_storage"));
    CHECK(std::stod(row.at("sampler_build_s")) > 0);
    // The exported table is the sampler of the exported factorization.
    const BrdfPtr f = Catalogue::global().make((run / "factors.json").string());
    SamplerOptions so;
    so.method = "tabulated";
    so.view_phi_bins = entry.at("view_phi_bins").get<int>();
    const auto want = make_sampler(*f, so);
    const auto got = tabulated_sampler(
        sampling_table_from(read_exr((run / "sampling.exr").string()), entry, "sampling.exr"));
    CHECK(got->storage_floats() == want->storage_floats());
    for (double u : {0.1, 0.5, 0.93}) {
      const Vec3 wo(0.6, 0.0, 0.8);
      CHECK((got->sample(wo, u, 1 - u).wi - want->sample(wo, u, 1 - u).wi).norm() < 1e-5);
    }
    const nlohmann::json rec = nlohmann::json::parse(slurp((run / "run.json").string()));
    REQUIRE(rec.contains("sampler"));
    CHECK(rec["sampler"].contains("cosine_fraction"));
    // run.json's "sampling" stays the sample set's description.
    CHECK(rec.at("sampling") == "grid 6^4");
  }
}

// A factorization never says it is isotropic (its terms read absolute
// azimuths), but one of an isotropic BRDF approximates an isotropic
// function: its table then has one view azimuth bin (the mean over view
// azimuths), 1/16 of the storage; of an anisotropic BRDF, 16 bins.
// (chi2 of such a table: tests/factor/sampling_test.cpp.)
namespace {
void check_view_phi_bins(const std::string& brdf, bool iso) {
  INFO(brdf);
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "cfg.toml", std::string(R"([experiment]
name = "t"
plots = false
render = false

[[brdf]]
)") + brdf + R"(

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "mccool"
texture_size = 8
sampler = true
)");
  const RunSummary s = run_quiet(cfg, tmp / "out");
  REQUIRE(s.failed == 0);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 1);
  CHECK(rows[0].at("isotropic") == (iso ? "true" : "false"));
  const fs::path run = fs::path(tmp / "out/runs") / rows[0].at("run_id");
  const nlohmann::json rec = nlohmann::json::parse(slurp((run / "run.json").string()));
  CHECK(rec.at("sampler").at("view_phi_bins").get<int>() == (iso ? 1 : 16));
  CHECK(rows[0].at("sampler_storage") == std::to_string((iso ? 1 : 16) * 16 * (33 + 32 * 65)));
}
}  // namespace

TEST_CASE("sampling: the sampler of a fit has one view azimuth bin when the fitted BRDF is isotropic") {
  check_view_phi_bins("preset = \"bluepaint\"", true);
}

TEST_CASE("sampling: the sampler of a fit of an anisotropic BRDF keeps 16 view azimuth bins", "[slow]") {
  check_view_phi_bins("model = \"ward\"\nax = 0.1\nay = 0.3", false);
}

// A run with sampling on records its Monte Carlo noise against samples
// (cosine and its own sampler at 4, 16, 64 spp) in run.json; with plots,
// report.html shows it (plot_results.py: noise_vs_spp).
namespace {
void check_noise_rows(bool plots) {
  ScratchDir tmp;
  const std::string cfg = write_text(tmp / "cfg.toml", R"([experiment]
name = "t"
render = false

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 6

[[method]]
kind = "sh-k"
order = 2
sampler = true
)");
  const RunSummary s = run_quiet(cfg, tmp / "out", {}, plots);
  REQUIRE(s.failed == 0);
  const auto rows = read_results_csv(tmp / "out/results.csv");
  REQUIRE(rows.size() == 1);
  const nlohmann::json rec =
      nlohmann::json::parse(slurp((fs::path(tmp / "out/runs") / rows[0].at("run_id") / "run.json").string()));
  const nlohmann::json& noise = rec.at("sampler").at("noise");
  REQUIRE(noise.size() == 6);
  std::map<std::string, std::vector<double>> rmse;
  for (const auto& n : noise) rmse[n.at("sampler").get<std::string>()].push_back(n.at("rmse").get<double>());
  for (const auto& [sampler, r] : rmse) {
    INFO(sampler);
    REQUIRE(r.size() == 3);
    for (double v : r) CHECK((std::isfinite(v) && v > 0));
    CHECK(r[2] < r[0]);  // 16x the samples: less noise
  }
  if (!plots) return;
  CHECK(fs::exists(tmp / "out/plots/noise_vs_spp.png"));
  CHECK(slurp(tmp / "out/report.html").find("plots/noise_vs_spp.png") != std::string::npos);
}
}  // namespace

TEST_CASE("sampling: a run with sampling on records its Monte Carlo noise against samples") {
  check_noise_rows(false);
}

TEST_CASE("sampling: report.html shows the noise against samples of a run with sampling on", "[slow]") {
  check_noise_rows(true);
}

TEST_CASE("sampling: sample-dirs prints n samples and names bad arguments") {
  std::string out;
  REQUIRE(run_cli("sample-dirs --brdf bluepaint --wo 0.6,0,0.8 -n 5 --view-bins 4 --theta-bins 8 --phi-bins 16", &out) == 0);
  std::istringstream in(out);
  int lines = 0;
  double x, y, z, p;
  while (in >> x >> y >> z >> p) {
    ++lines;
    CHECK(z > 0);
    CHECK(p > 0);
  }
  CHECK(lines == 5);
  CHECK(run_cli("sample-dirs --brdf bluepaint --wo 0.6,0,-0.8", &out) == 2);
  CHECK(out.find("--wo") != std::string::npos);
  CHECK(run_cli("sample-dirs --brdf bluepaint --wo 0,0,1 -n 0", &out) == 2);
  CHECK(out.find("-n") != std::string::npos);
  CHECK(run_cli("sample-dirs --brdf bluepaint --wo 0,0,1 --theta-bins 1", &out) == 2);
  CHECK(out.find("theta_bins") != std::string::npos);
  CHECK(run_cli("sample-dirs --brdf bluepaint --wo 0,0,1 --method bogus", &out) == 2);
  CHECK(out.find("--method") != std::string::npos);
}
