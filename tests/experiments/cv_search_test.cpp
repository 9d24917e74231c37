// Keys chosen by held-out error beyond mccool/fit smoothing (docs/design.md
// §4.1 "cv"): `smoothing = "cv"` for the search (one search at the base
// smoothing, its projections refit per candidate), `texture_size = "cv"`
// (mccool, fit, search) and both at once (a grid). Planted cases: noisy
// samples of a smooth BRDF, where heavy smoothing must win, and few samples,
// where the largest texture overfits.
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

// n samples of a smooth BRDF with log-normal noise sigma per channel, as a CSV.
std::string noisy_csv(const ScratchDir& tmp, const std::string& brdf, size_t n, double sigma) {
  const BrdfPtr bp = Catalogue::builtin().make(brdf);
  SampleSet s = sample_stratified(*bp, n, 5);
  Normal g{23};
  for (auto& v : s.value)
    for (int c = 0; c < 3; ++c) v[c] *= std::exp(sigma * g());
  const std::string path = tmp / "noisy.csv";
  write_sample_csv(s, path);
  return path;
}

std::string config(const std::string& csv, const std::string& experiment, const std::string& method) {
  return "[experiment]\nseed = 2\nplots = false\nrender = false\nexport = false\nvalidation_pairs = 0\n" +
         experiment + "[[brdf]]\nfile = \"" + csv + "\"\n[sampling]\nkind = \"measured\"\n[[method]]\n" + method;
}

// A fast search: one term, one start, greedy, on every sample.
const char* const kSearch =
    "kind = \"search\"\nterms = 1\nrestarts = 1\nthreads = 1\nstrategy = \"greedy\"\nsearch_samples = \"off\"\n";

struct CvRun {
  std::map<std::string, std::string> row;
  nlohmann::json rec;
};

CvRun run_one(const ScratchDir& tmp, const std::string& name, const std::string& text) {
  const std::string out = tmp / name;
  run_quiet(write_text(out + ".toml", text), out);
  const auto rows = read_results_csv(out + "/results.csv");
  REQUIRE(rows.size() == 1);
  CvRun r;
  r.row = rows[0];
  INFO(r.row.at("notes"));
  REQUIRE(r.row.at("status") == "ok");
  r.rec = nlohmann::json::parse(read_text(out + "/runs/" + r.row.at("run_id") + "/run.json"));
  return r;
}

// The candidate with the lowest held-out rel_mse (the first of equal ones).
size_t argmin(const nlohmann::json& cands) {
  size_t best = 0;
  for (size_t i = 0; i < cands.size(); ++i)
    if (cands[i].at("holdout_rel_mse").get<double>() < cands[best].at("holdout_rel_mse").get<double>()) best = i;
  return best;
}

}  // namespace

TEST_CASE("cv: the search with smoothing = cv refits its projections per candidate and heavy smoothing wins on noise") {
  ScratchDir tmp;
  // Few, very noisy samples of a smooth BRDF: each texel sees about one
  // sample, so only heavy smoothing keeps the noise out of the textures.
  const std::string csv = noisy_csv(tmp, "lambert", 500, 0.5);
  const CvRun r = run_one(tmp, "s", config(csv, "holdout = 0.25\n", std::string(kSearch) +
                                                                           "texture_size = 16\nsmoothing = \"cv\"\n"));
  const auto& cv = r.rec.at("cv");
  CHECK(cv.at("key") == "smoothing");
  REQUIRE(cv.at("candidates").size() == kCvSmoothingLadder.size());
  const size_t best = argmin(cv.at("candidates"));
  const double chosen = cv.at("chosen").get<double>();
  CHECK(chosen == kCvSmoothingLadder[best]);
  CHECK(chosen >= 0.1);  // the planted answer: heavy smoothing
  CHECK(r.row.at("notes").find("smoothing = \"cv\" chose " + format_short(format_number(chosen))) != std::string::npos);
  CHECK(std::stod(r.row.at("holdout_rel_mse")) ==
        Approx(cv["candidates"][best].at("holdout_rel_mse").get<double>()).epsilon(1e-6));
  // The search ran once on the training samples at the base smoothing; the
  // run's own fit (the same training samples) reused it.
  const auto& sc = r.rec.at("search_cv");
  CHECK(sc.at("base_smoothing").get<double>() == 1e-3);
  CHECK(sc.at("base_texture_size").get<int>() == 16);
  CHECK(sc.at("search") == "reused");
  CHECK(sc.at("smoothing").get<double>() == chosen);
}

TEST_CASE("cv: texture_size = cv keeps the largest texture from overfitting few samples and reports its storage") {
  ScratchDir tmp;
  const std::string csv = noisy_csv(tmp, "lambert", 300, 0.3);
  const CvRun r =
      run_one(tmp, "t", config(csv, "holdout = 0.3\n", "kind = \"mccool\"\ntexture_size = \"cv\"\n"));
  const auto& cv = r.rec.at("cv");
  CHECK(cv.at("key") == "texture_size");
  REQUIRE(cv.at("candidates").size() == kCvTextureLadder.size());
  const size_t best = argmin(cv.at("candidates"));
  const int chosen = cv.at("chosen").get<int>();
  CHECK(chosen == kCvTextureLadder[best]);
  CHECK(chosen < kCvTextureLadder.back());  // the largest overfits
  CHECK(cv["candidates"].back().at("holdout_rel_mse").get<double>() >
        cv["candidates"][best].at("holdout_rel_mse").get<double>());
  CHECK(r.row.at("texture_size") == std::to_string(chosen));
  CHECK(r.row.at("notes").find("texture_size = \"cv\" chose " + std::to_string(chosen)) != std::string::npos);
  // storage_floats is the chosen size's: a fixed-size run of it stores the same.
  const CvRun fixed = run_one(tmp, "f", config(csv, "holdout = 0.3\n", "kind = \"mccool\"\ntexture_size = " +
                                                                           std::to_string(chosen) + "\n"));
  CHECK(r.row.at("storage_floats") == fixed.row.at("storage_floats"));
  CHECK(r.row.at("rel_mse") == fixed.row.at("rel_mse"));
}

TEST_CASE("cv: texture_size and smoothing = cv together try their grid and record both values") {
  ScratchDir tmp;
  const std::string csv = noisy_csv(tmp, "lambert", 200, 0.3);
  // The fit on the held-out fraction, the search on folds (a search per fold).
  for (const auto& [method, experiment] :
       {std::pair<std::string, std::string>{"kind = \"fit\"\nprojections = [{ name = \"wi\" }, { name = \"wo\" }]\n",
                                            "holdout = 0.3\n"},
        std::pair<std::string, std::string>{kSearch, "folds = 2\n"}}) {
    INFO(method);
    const CvRun r = run_one(tmp, method.substr(8, 3),
                            config(csv, experiment, method + "texture_size = \"cv\"\nsmoothing = \"cv\"\n"));
    const auto& cv = r.rec.at("cv");
    CHECK(cv.at("key") == "texture_size and smoothing");
    const auto& cands = cv.at("candidates");
    REQUIRE(cands.size() == kCvTextureLadder.size() * kCvSmoothingLadder.size());
    for (size_t i = 0; i < cands.size(); ++i) {
      CHECK(cands[i].at("texture_size").get<int>() == kCvTextureLadder[i / kCvSmoothingLadder.size()]);
      CHECK(cands[i].at("smoothing").get<double>() == kCvSmoothingLadder[i % kCvSmoothingLadder.size()]);
    }
    const size_t best = argmin(cands);
    CHECK(cv.at("chosen_values").at("texture_size") == cands[best].at("texture_size"));
    CHECK(cv.at("chosen_values").at("smoothing") == cands[best].at("smoothing"));
    CHECK(r.row.at("texture_size") == std::to_string(cands[best].at("texture_size").get<int>()));
    CHECK(r.row.at("notes").find("texture_size and smoothing = \"cv\" chose") != std::string::npos);
    CHECK(std::stod(r.row.at("holdout_rel_mse")) ==
          Approx(cands[best].at("holdout_rel_mse").get<double>()).epsilon(1e-6));
    // The search ran once per fold and once on every sample, never per candidate.
    if (r.rec.contains("search_cv")) CHECK(r.rec.at("search_cv").at("search") == "ran");
  }
}

TEST_CASE("cv: texture_size = cv is rejected where nothing is held out and with what it cannot combine") {
  require_one_config_error(std::string(kConfigHead) + "[[method]]\nkind = \"mccool\"\ntexture_size = \"cv\"\n",
                           {"method.texture_size", "cv", "grid"});
  require_one_config_error(std::string(kConfigHead) +
                               "[[method]]\nkind = \"search\"\nterms = 1\ntexture_size = \"cv\"\n",
                           {"method.texture_size", "cv", "grid"});
  require_one_config_error(std::string(kConfigHead) +
                               "[[method]]\nkind = \"mccool\"\ntexture_size = \"cv\"\ntexture_ladder = [4, 8]\n",
                           {"texture_ladder"});
  // Any other value names every accepted form (the search has no "auto").
  require_one_config_error(std::string(kConfigHead) + "[[method]]\nkind = \"search\"\ntexture_size = \"cvx\"\n",
                           {"texture_size: expected an integer in 2..1024 or \"cv\", found \"cvx\""});
  for (const char* kind : {"kind = \"mccool\"\n", "kind = \"fit\"\nprojections = [{ name = \"wi\" }, { name = \"wo\" }]\n"})
    require_one_config_error(std::string(kConfigHead) + "[[method]]\n" + kind + "texture_size = 16.5\n",
                             {"texture_size: expected an integer in 2..1024, \"auto\" or \"cv\", found 16.5"});
  require_one_config_error(
      std::string(kConfigHead) +
          "[[method]]\nkind = \"search\"\nsmoothing = \"cv\"\ntolerance = { metric = \"rel_mse\", value = 0.1 }\n",
      {"smoothing", "cv", "tolerance"});
}
