// The tabulating baselines (svd, sh-k, sh-r) of a measured BRDF see only the
// training samples (experiments/run/runner.cpp, measured_from_training), so
// their held-out columns are on unseen data.
#include "brdfs/catalogue.h"
#include "brdfs/sample_csv.h"
#include "experiments/config/config.h"
#include "experiments/report/outputs.h"
#include "experiments/report/validation.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

TEST_CASE("baselines never see held-out samples - perturbing only them leaves svd and sh-k unchanged") {
  ScratchDir tmp;
  const BrdfPtr bp = Catalogue::builtin().make("bluepaint");
  SampleSet s = sample_stratified(*bp, 600, 4);
  const std::string clean = tmp / "clean.csv";
  write_sample_csv(s, clean);
  const SampleSet loaded = read_sample_csv(clean);
  const uint64_t seed = 5;
  const HoldoutSplit split = split_holdout(loaded, 0.1, validation_seed(seed));
  REQUIRE(split.held.valid_count() == 60);
  // The same list with the held-out samples' values x 7.
  SampleSet perturbed = loaded;
  size_t changed = 0;
  for (size_t k = 0; k < perturbed.size(); ++k)
    for (size_t h = 0; h < split.held.size(); ++h)
      if (split.held.wi[h] == loaded.wi[k] && split.held.wo[h] == loaded.wo[k]) {
        perturbed.value[k] *= 7.0;
        ++changed;
      }
  REQUIRE(changed == 60);
  const std::string bad = tmp / "perturbed.csv";
  write_sample_csv(perturbed, bad);

  auto config = [&](const std::string& csv) {
    return "[experiment]\nseed = 5\nholdout = 0.1\nplots = false\nrender = false\nexport = false\n"
           "[[brdf]]\nfile = \"" + csv + "\"\n[sampling]\nkind = \"measured\"\n"
           "[[method]]\nkind = \"svd\"\nterms = 2\ntexture_size = 6\n"
           "[[method]]\nkind = \"sh-k\"\norder = 3\ntexture_size = 6\n";
  };
  run_quiet(write_text(tmp / "a.toml", config(clean)), tmp / "a");
  run_quiet(write_text(tmp / "b.toml", config(bad)), tmp / "b");
  const auto ra = read_results_csv(tmp / "a/results.csv"), rb = read_results_csv(tmp / "b/results.csv");
  REQUIRE(ra.size() == 2);
  REQUIRE(rb.size() == 2);
  for (size_t i = 0; i < 2; ++i) {
    INFO(ra[i].at("method"));
    // Identical training metrics and shading of the training data...
    for (const char* k : {"rel_mse", "cos_rmse", "lin_rmse"}) CHECK(ra[i].at(k) == rb[i].at(k));
    // ...while the held-out metric sees the perturbation.
    CHECK(std::stod(rb[i].at("holdout_rel_mse")) > std::stod(ra[i].at("holdout_rel_mse")) + 1.0);
  }
}
