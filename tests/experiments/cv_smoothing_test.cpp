// `smoothing = "cv"` (mccool, fit): the smoothing is chosen from
// kCvSmoothingLadder by held-out error, recorded in the row's notes and in
// run.json, and the run's fit uses the choice. Planted case: noisy samples of
// a smooth BRDF, where too little smoothing fits the noise and too much
// flattens the BRDF, so the held-out error is lowest at a middle value.
#include <catch2/catch.hpp>
#include <cmath>

#include "brdfs/catalogue.h"
#include "brdfs/sample_csv.h"
#include "experiments/methods/homomorphic.h"
#include "experiments/report/outputs.h"
#include "experiments_helpers.h"
#include "normal_stream.h"

using namespace bf;
using namespace bf_test;

namespace {

// Noisy samples (log-normal, sigma 0.05 per channel) of a glossy Cook-Torrance
// as a CSV. Measured with the CLI (holdout 0.2, texture 16): held-out rel_mse
// 0.144, 0.143, 0.142, 0.146, 0.175 for smoothing 1e-4 ... 1: the highlight
// needs little smoothing, the noise some.
std::string noisy_csv(const ScratchDir& tmp) {
  const BrdfPtr bp = Catalogue::builtin().make("cook-torrance:m=0.15");
  SampleSet s = sample_stratified(*bp, 6000, 3);
  Normal n{17};
  for (auto& v : s.value)
    for (int c = 0; c < 3; ++c) v[c] *= std::exp(0.05 * n());
  const std::string path = tmp / "noisy.csv";
  write_sample_csv(s, path);
  return path;
}

std::string config(const std::string& csv, const std::string& experiment) {
  return "[experiment]\nseed = 2\nplots = false\nrender = false\nexport = false\nvalidation_pairs = 0\n" +
         experiment + "[[brdf]]\nfile = \"" + csv + "\"\n[sampling]\nkind = \"measured\"\n" +
         "[[method]]\nkind = \"mccool\"\ntexture_size = 16\nsmoothing = \"cv\"\n";
}

}  // namespace

TEST_CASE("cv: smoothing = cv picks the middle value that a noisy smooth BRDF needs and records it") {
  ScratchDir tmp;
  const std::string csv = noisy_csv(tmp);
  for (const std::string& exp : {std::string("holdout = 0.2\n"), std::string("folds = 3\n")}) {
    INFO(exp);
    std::string name = "o";  // not "o" + std::to_string(...): GCC 12 warns falsely there (-Wrestrict)
    name += std::to_string(exp.size());
    const std::string out = tmp / name;
    run_quiet(write_text(out + ".toml", config(csv, exp)), out);
    const auto rows = read_results_csv(out + "/results.csv");
    REQUIRE(rows.size() == 1);
    const auto& r = rows[0];
    INFO(r.at("notes"));
    REQUIRE(r.at("status") == "ok");
    const nlohmann::json rec = nlohmann::json::parse(read_text(out + "/runs/" + r.at("run_id") + "/run.json"));
    const auto& cv = rec.at("cv");
    REQUIRE(cv.at("candidates").size() == kCvSmoothingLadder.size());
    size_t best = 0;
    for (size_t i = 0; i < cv.at("candidates").size(); ++i) {
      CHECK(cv["candidates"][i].at("value").get<double>() == kCvSmoothingLadder[i]);
      if (cv["candidates"][i].at("holdout_rel_mse").get<double>() <
          cv["candidates"][best].at("holdout_rel_mse").get<double>())
        best = i;
    }
    const double chosen = cv.at("chosen").get<double>();
    CHECK(chosen == kCvSmoothingLadder[best]);
    // The planted case: neither end of the ladder.
    CHECK(chosen > kCvSmoothingLadder.front());
    CHECK(chosen < kCvSmoothingLadder.back());
    // The row says what was chosen, and its held-out error is the choice's.
    CHECK(r.at("notes").find("smoothing = \"cv\" chose " + format_short(format_number(chosen))) !=
          std::string::npos);
    CHECK(std::stod(r.at("holdout_rel_mse")) ==
          Approx(cv["candidates"][best].at("holdout_rel_mse").get<double>()).epsilon(1e-6));
  }
}

TEST_CASE("cv: smoothing = cv is rejected where nothing is held out") {
  const std::string m = "[[method]]\nkind = \"mccool\"\ntexture_size = 4\nsmoothing = \"cv\"\n";
  require_one_config_error(std::string(kConfigHead) + m, {"smoothing", "cv", "grid"});
  // The search takes "cv" too, with the same rule.
  require_one_config_error(std::string(kConfigHead) +
                               "[[method]]\nkind = \"search\"\nterms = 1\ntexture_size = 4\nsmoothing = \"cv\"\n",
                           {"method.smoothing", "cv", "grid"});
  // Any other value names both accepted forms and what was found.
  require_one_config_error(std::string(kConfigHead) + "[[method]]\nkind = \"mccool\"\nsmoothing = \"cvx\"\n",
                           {"smoothing: expected a number in [0, ", "] or \"cv\", found \"cvx\""});
  require_one_config_error(std::string(kConfigHead) + "[[method]]\nkind = \"search\"\nsmoothing = true\n",
                           {"smoothing: expected a number in [0, ", "] or \"cv\", found true"});
}
