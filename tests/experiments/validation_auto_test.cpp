// The default whole-domain set, validation_pairs = "auto"
// (experiments/report/validation.h, docs/design.md §4.1): independent
// stratified blocks, scored until val_rel_mse is precise.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <set>
#include <vector>

#include "brdfs/catalogue.h"
#include "brdfs/models.h"
#include "experiments/report/outputs.h"
#include "experiments/report/validation.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

constexpr int kBlock = ExperimentSettings::kValidationBlockPairs;

// The first n pairs of a set (the prefix an "auto" domain scored).
SampleSet first_samples(const SampleSet& s, size_t n) {
  if (n >= s.size()) return s;
  SampleSet p;
  p.wi.assign(s.wi.begin(), s.wi.begin() + n);
  p.wo.assign(s.wo.begin(), s.wo.begin() + n);
  p.value.assign(s.value.begin(), s.value.begin() + n);
  p.valid.assign(s.valid.begin(), s.valid.begin() + n);
  if (!s.weight.empty()) p.weight.assign(s.weight.begin(), s.weight.begin() + n);
  p.description = "the first " + std::to_string(n) + " pairs of " + s.description;
  p.symmetries = s.symmetries;
  return p;
}

// The wrapped BRDF, times `gain` where wo is within `radius` (radians) of the
// mirror direction of wi and wi is beyond 60 degrees from the normal: an
// approximation wrong only on a small off-axis region, whose error the
// per-axis strata of the set do not spread evenly over the blocks.
class Spike : public Brdf {
 public:
  Spike(BrdfPtr b, double gain, double radius) : b_(std::move(b)), gain_(gain), cos_r_(std::cos(radius)) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    const Vec3 mirror(-wi.x(), -wi.y(), wi.z());
    const bool in = wi.z() < 0.5 && mirror.dot(wo) > cos_r_;
    return (in ? gain_ : 1.0) * b_->eval(wi, wo);
  }
  std::string name() const override { return "spike"; }
  std::string to_string() const override { return "spike"; }

 private:
  BrdfPtr b_;
  double gain_, cos_r_;
};

}  // namespace

TEST_CASE("validation auto: 64 independent blocks, block 0 is the 4096-pair set of the same seed") {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const DomainSet d = domain_set(*b, ExperimentSettings::kValidationAuto, 77);
  CHECK(d.block_pairs == kBlock);
  CHECK(d.blocks == ExperimentSettings::kValidationMaxBlocks);
  REQUIRE(d.pairs.size() == size_t(d.blocks) * kBlock);
  CHECK(d.pairs.valid_count() == d.pairs.size());
  const SampleSet first = validation_set(*b, kBlock, 77);
  for (size_t k = 0; k < first.size(); k += 97) {
    CHECK(d.pairs.wi[k] == first.wi[k]);
    CHECK(d.pairs.wo[k] == first.wo[k]);
  }
  // The blocks are different draws (no block repeats another's first pair).
  std::set<std::pair<double, double>> starts;
  for (int blk = 0; blk < d.blocks; ++blk) starts.insert({d.pairs.wi[size_t(blk) * kBlock].x(), d.pairs.wo[size_t(blk) * kBlock].y()});
  CHECK(starts.size() == size_t(d.blocks));
  std::set<uint64_t> seeds;
  for (int blk = 0; blk < d.blocks; ++blk) seeds.insert(validation_block_seed(77, blk));
  CHECK(seeds.size() == size_t(d.blocks));
  CHECK(validation_block_seed(77, 0) == 77);
  // A number of pairs: one set scored whole, as before.
  const DomainSet n = domain_set(*b, 1000, 77);
  CHECK(n.block_pairs == 0);
  CHECK(n.pairs.size() == 1000);
  CHECK_THROWS_WITH(domain_set(*b, 0, 77), Catch::Contains("validation_pairs") && Catch::Contains("found 0"));
}

TEST_CASE("validation auto: relative standard error has its closed form") {
  CHECK(relative_standard_error({1.0, 2.0, 3.0}) == Approx(1.0 / std::sqrt(3.0) / 2.0));
  CHECK(relative_standard_error({0.5, 0.5, 0.5, 0.5}) == 0.0);
  CHECK(relative_standard_error({0.0, 0.0}) == 0.0);
  CHECK(std::isinf(relative_standard_error({0.3})));
  CHECK(std::isinf(relative_standard_error({})));
}

TEST_CASE("validation auto: the scores are those of the prefix scored, and more blocks only when imprecise") {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const DomainSet d = domain_set(*b, ExperimentSettings::kValidationAuto, 5);
  const LogTransform lt = LogTransform::of(d.pairs);
  const auto check_prefix = [&](const Brdf& approx, const ValidationScores& v) {
    REQUIRE(v.domain);
    REQUIRE(v.pairs == size_t(v.blocks) * kBlock);
    const SampleSet p = first_samples(d.pairs, v.pairs);
    const Metrics m = evaluate_metrics(approx, p, lt);
    CHECK(v.val.rel_mse == m.rel_mse);
    CHECK(v.val.cos_rmse == m.cos_rmse);
    CHECK(v.val.samples == p.valid_count());
    CHECK(v.max_ratio == peak_ratio(approx, p));
    for (int c = 0; c < 3; ++c) CHECK(v.val.rel_mse_channel[c] == Approx(m.rel_mse_channel[c]));
    CHECK((v.val.rel_mse_channel[0] + v.val.rel_mse_channel[1] + v.val.rel_mse_channel[2]) / 3 ==
          Approx(v.val.rel_mse).epsilon(1e-12));
    // The rule: stopped at the target, or at the last block.
    CHECK((v.rel_se <= ExperimentSettings::kValidationTargetSe || v.blocks == d.blocks));
    if (v.blocks > ExperimentSettings::kValidationMinBlocks) {
      // Half as many blocks were not precise enough.
      std::vector<double> half;
      for (int blk = 0; blk < v.blocks / 2; ++blk) {
        std::vector<Rgb> values(d.pairs.size(), Rgb::Zero());
        const size_t b0 = size_t(blk) * kBlock;
        for (size_t k = b0; k < b0 + kBlock; ++k) values[k] = approx.eval(d.pairs.wi[k], d.pairs.wo[k]);
        half.push_back(metrics_of_values(d.pairs, b0, b0 + kBlock, values, lt).rel_mse);
      }
      CHECK(relative_standard_error(half) > ExperimentSettings::kValidationTargetSe);
    }
  };
  // The truth itself: error 0 everywhere, the first 8 blocks suffice.
  const ValidationScores exact = score_validation(*b, &d, nullptr, lt);
  CHECK(exact.blocks == ExperimentSettings::kValidationMinBlocks);
  CHECK(exact.rel_se == 0.0);
  CHECK(exact.val.rel_mse == 0.0);
  check_prefix(*b, exact);
  // Wrong on a small region only: the error is a rare event and needs more blocks.
  const Spike spike(b, 20.0, 0.12);
  const ValidationScores rare = score_validation(spike, &d, nullptr, lt);
  INFO("blocks " << rare.blocks << " rel_se " << rare.rel_se << " val " << rare.val.rel_mse);
  CHECK(rare.val.rel_mse > 0.0);
  CHECK(rare.blocks > ExperimentSettings::kValidationMinBlocks);
  check_prefix(spike, rare);
  // Wrong everywhere (a Lambertian for the paint): an error spread over the
  // domain is precise with fewer blocks than the rare one.
  const Lambert lambert{LambertParams{}};
  const ValidationScores broad = score_validation(lambert, &d, nullptr, lt);
  CHECK(broad.blocks < rare.blocks);
  check_prefix(lambert, broad);
}

TEST_CASE("validation auto: the default of a config, recorded in the row, run.json and the run identity") {
  ScratchDir tmp;
  const std::string cfg = std::string(kConfigHead) +
                          "[[method]]\nkind = \"svd\"\nterms = 1\ntexture_size = 6\n";
  register_loaders();
  CHECK(parse_plan(cfg, "cfg.toml").experiment.validation_pairs == ExperimentSettings::kValidationAuto);
  CHECK(parse_plan(cfg, "cfg.toml", {"experiment.validation_pairs=\"auto\""}).experiment.validation_pairs ==
        ExperimentSettings::kValidationAuto);
  CHECK(parse_plan(cfg, "cfg.toml", {"experiment.validation_pairs=4096"}).experiment.validation_pairs == 4096);
  const auto errs = config_errors(cfg, {"experiment.validation_pairs=\"many\""});
  REQUIRE(errs.size() == 1);
  CHECK_THAT(errs[0], Catch::Contains("validation_pairs") && Catch::Contains("auto") && Catch::Contains("many"));
  // The identity: "auto" and 4096 are different sets, so different runs.
  const Plan pa = parse_plan(cfg, "cfg.toml"), pn = parse_plan(cfg, "cfg.toml", {"experiment.validation_pairs=4096"});
  CHECK(pa.runs.at(0).run_id != pn.runs.at(0).run_id);

  const std::string body = "[experiment]\nname = \"v\"\nplots = false\nrender = false\nexport = false\n"
                           "[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = \"grid\"\nresolution = 6\n"
                           "[[method]]\nkind = \"svd\"\nterms = 1\ntexture_size = 6\n";
  run_quiet(write_text(tmp / "a.toml", body), tmp / "a");
  run_quiet(write_text(tmp / "b.toml", body), tmp / "b", {"experiment.validation_pairs=4096"});
  const Row ra = read_results_csv(tmp / "a/results.csv").at(0), rb = read_results_csv(tmp / "b/results.csv").at(0);
  REQUIRE(ra.at("status") == "ok");
  REQUIRE(rb.at("status") == "ok");
  CHECK_THAT(ra.at("validation"), Catch::Contains("validation_pairs = \"auto\"") &&
                                      Catch::Contains("blocks of 4096") && Catch::Contains("standard error"));
  CHECK_THAT(rb.at("validation"), Catch::Contains("domain: 4096 stratified pairs (seed") &&
                                      !Catch::Contains("blocks"));
  const auto rec = nlohmann::json::parse(read_text(tmp / ("a/runs/" + ra.at("run_id") + "/run.json")));
  const auto& v = rec.at("validation");
  const int blocks = v.at("blocks").get<int>();
  CHECK(blocks >= ExperimentSettings::kValidationMinBlocks);
  CHECK(blocks <= ExperimentSettings::kValidationMaxBlocks);
  CHECK(v.at("pairs").get<size_t>() == size_t(blocks) * kBlock);
  CHECK(v.at("val_rel_mse_standard_error").get<double>() >= 0.0);
  const auto rec_b = nlohmann::json::parse(read_text(tmp / ("b/runs/" + rb.at("run_id") + "/run.json")));
  CHECK(rec_b.at("validation").at("pairs").get<size_t>() == 4096);
  CHECK_FALSE(rec_b.at("validation").contains("blocks"));
}
