// k-fold hold-out (experiments/run/folds.h, `[experiment] folds`): folds are
// disjoint, cover every valid sample once, are seeded and deterministic; the
// runner reports the folds' mean held-out error, fits the exported
// factorization on every sample, and rejects bad values naming the key.
#include <catch2/catch.hpp>
#include <cmath>
#include <set>
#include <vector>

#include "brdfs/catalogue.h"
#include "brdfs/sample_csv.h"
#include "experiments/report/outputs.h"
#include "experiments/report/validation.h"
#include "experiments/run/folds.h"
#include "experiments_helpers.h"

using namespace bf;
using namespace bf_test;

namespace {

// n samples whose red value is their index; every 7th (from 4) is masked.
SampleSet kfold_set(int n) {
  SampleSet s;
  for (int k = 0; k < n; ++k) {
    const double phi = 0.1 * k;
    s.push(Vec3(0, 0, 1), Vec3(0.6 * std::cos(phi), 0.6 * std::sin(phi), 0.8),
           Rgb(double(k), k % 7 == 4 ? -1.0 : 1.0, 1.0), 1.0 + k);
  }
  s.validate();
  return s;
}

std::vector<int> indices(const SampleSet& s) {
  std::vector<int> v;
  for (size_t k = 0; k < s.size(); ++k) v.push_back(static_cast<int>(s.value[k][0]));
  return v;
}

}  // namespace

TEST_CASE("kfold: folds are disjoint and cover every valid sample once - masked ones stay in training") {
  const SampleSet s = kfold_set(60);  // 52 valid
  for (int k : {2, 3, 5, 52}) {
    INFO("k = " << k);
    const std::vector<HoldoutSplit> f = split_folds(s, k, 9);
    REQUIRE(f.size() == static_cast<size_t>(k));
    std::vector<int> held_count(60, 0);
    size_t lo = 1000, hi = 0;
    for (const HoldoutSplit& h : f) {
      lo = std::min(lo, h.held.size());
      hi = std::max(hi, h.held.size());
      REQUIRE(h.train.size() + h.held.size() == 60);
      const std::vector<int> held = indices(h.held), train = indices(h.train);
      const std::set<int> in_train(train.begin(), train.end());
      for (size_t j = 0; j < held.size(); ++j) {
        const int i = held[j];
        ++held_count[i];
        CHECK(in_train.count(i) == 0);
        CHECK(h.held.weight[j] == 1.0 + i);  // weights follow their samples
      }
      CHECK(in_train.size() + held.size() == 60);
    }
    CHECK(hi - lo <= 1);  // fold sizes differ by at most one
    for (int i = 0; i < 60; ++i) CHECK(held_count[i] == (i % 7 == 4 ? 0 : 1));
  }
}

TEST_CASE("kfold: folds are seeded and deterministic") {
  const SampleSet s = kfold_set(60);
  const auto a = split_folds(s, 4, 3), b = split_folds(s, 4, 3), c = split_folds(s, 4, 4);
  bool differ = false;
  for (size_t f = 0; f < 4; ++f) {
    CHECK(indices(a[f].held) == indices(b[f].held));
    differ = differ || indices(a[f].held) != indices(c[f].held);
  }
  CHECK(differ);
}

TEST_CASE("kfold: a number of folds out of range is rejected naming the key and the count") {
  const SampleSet s = kfold_set(10);  // 9 valid
  CHECK_THROWS_WITH(split_folds(s, 1, 1), Catch::Contains("experiment.folds") && Catch::Contains("found 1"));
  CHECK_THROWS_WITH(split_folds(s, 10, 1), Catch::Contains("experiment.folds") && Catch::Contains("9 valid") &&
                                                Catch::Contains("found 10"));
  CHECK_NOTHROW(split_folds(s, 9, 1));
  CHECK_THROWS_WITH(split_folds(kfold_set(3), 2, 1), Catch::Contains("experiment.folds"));
}

TEST_CASE("kfold: the summary is the folds' mean with their spread") {
  std::vector<Metrics> m(3);
  m[0].rel_mse = 1, m[1].rel_mse = 2, m[2].rel_mse = 6;
  m[0].cos_rmse = 0.1, m[1].cos_rmse = 0.2, m[2].cos_rmse = 0.6;
  const FoldSummary s = summarize_folds(m);
  CHECK(s.folds == 3);
  CHECK(s.rel_mse_mean == Approx(3.0));
  CHECK(s.rel_mse_sd == Approx(std::sqrt(7.0)));  // ((4 + 1 + 9) / 2)^(1/2)
  CHECK(s.rel_mse_min == 1.0);
  CHECK(s.rel_mse_max == 6.0);
  CHECK(s.cos_rmse_mean == Approx(0.3));
  CHECK(s.spread().find("3 folds") != std::string::npos);
}

TEST_CASE("kfold: config rejects folds = 1 and folds with an explicit holdout") {
  const std::string head = std::string(kConfigHead) + "[[method]]\nkind = \"mccool\"\ntexture_size = 4\n";
  auto with = [&](const std::string& exp) {
    std::string t = head;
    t.replace(t.find("name = \"t\"\n"), 11, "name = \"t\"\n" + exp);
    return t;
  };
  require_one_config_error(with("folds = 1\n"), {"experiment.folds", "found 1", "2"});
  require_one_config_error(with("folds = 5\nholdout = 0.2\n"), {"experiment.folds", "holdout"});
  CHECK(config_errors(with("folds = 5\n")).empty());
  // folds enter the run identity; absent, the identity is as before.
  register_loaders();
  const Plan a = parse_plan(with(""), "cfg.toml", {}), b = parse_plan(with("folds = 5\n"), "cfg.toml", {}),
             c = parse_plan(with("folds = 3\n"), "cfg.toml", {});
  CHECK(a.runs[0].run_id != b.runs[0].run_id);
  CHECK(b.runs[0].run_id != c.runs[0].run_id);
  CHECK(!a.runs[0].identity["validation"].contains("folds"));
}

TEST_CASE("kfold: folds = auto holds out 5 folds of small raw sets and the single fraction of large ones") {
  // The rule (experiments/report/validation.h folds_for).
  SamplingVariant raw, grid;
  raw.kind = "measured";
  grid.kind = "grid";
  const ExperimentSettings autoset;  // the defaults: folds = "auto", holdout 0.1
  REQUIRE(autoset.folds == ExperimentSettings::kFoldsAuto);
  CHECK(folds_for(raw, autoset, 1439) == 5);
  CHECK(folds_for(raw, autoset, ExperimentSettings::kAutoFoldsMaxSamples) == 5);
  CHECK(folds_for(raw, autoset, ExperimentSettings::kAutoFoldsMaxSamples + 1) == 0);
  CHECK(folds_for(raw, autoset, 986594) == 0);
  CHECK(folds_for(grid, autoset, 1439) == 0);
  ExperimentSettings three = autoset, single = autoset;
  three.folds = 3;
  single.folds = 0;
  CHECK(folds_for(raw, three, 986594) == 3);
  CHECK(folds_for(raw, single, 1439) == 0);

  // The config: "auto" is the default, setting holdout chooses the single
  // fraction, "auto" with holdout or another word is refused.
  register_loaders();
  const std::string head = std::string(kConfigHead) + "[[method]]\nkind = \"mccool\"\ntexture_size = 4\n";
  auto with = [&](const std::string& exp) {
    std::string t = head;
    t.replace(t.find("name = \"t\"\n"), 11, "name = \"t\"\n" + exp);
    return t;
  };
  CHECK(parse_plan(with(""), "cfg.toml", {}).experiment.folds == ExperimentSettings::kFoldsAuto);
  CHECK(parse_plan(with("folds = \"auto\"\n"), "cfg.toml", {}).experiment.folds == ExperimentSettings::kFoldsAuto);
  CHECK(parse_plan(with("holdout = 0.1\n"), "cfg.toml", {}).experiment.folds == 0);
  CHECK(parse_plan(with("folds = 0\n"), "cfg.toml", {}).experiment.folds == 0);
  require_one_config_error(with("folds = \"auto\"\nholdout = 0.2\n"), {"experiment.folds", "auto", "holdout"});
  require_one_config_error(with("folds = \"some\"\n"), {"experiment.folds", "auto", "some"});

  // A run on a small raw set: 5 folds by default, the single 10% fraction
  // when holdout is set; "auto" is in the identity of raw-sample runs only.
  ScratchDir tmp;
  const BrdfPtr bp = Catalogue::builtin().make("bluepaint");
  const std::string csv = tmp / "s.csv";
  write_sample_csv(sample_stratified(*bp, 200, 4), csv);
  const std::string body = "plots = false\nrender = false\nexport = false\nvalidation_pairs = 0\n"
                           "[[brdf]]\nfile = \"" + csv + "\"\n[sampling]\nkind = \"measured\"\n"
                           "[[method]]\nkind = \"mccool\"\ntexture_size = 6\n";
  run_quiet(write_text(tmp / "a.toml", "[experiment]\n" + body), tmp / "a");
  run_quiet(write_text(tmp / "b.toml", "[experiment]\nholdout = 0.1\n" + body), tmp / "b");
  const auto ra = read_results_csv(tmp / "a/results.csv"), rb = read_results_csv(tmp / "b/results.csv");
  REQUIRE(ra.size() == 1);
  REQUIRE(rb.size() == 1);
  INFO(ra[0].at("validation") << " | " << rb[0].at("validation"));
  CHECK(ra[0].at("validation").find("5-fold (folds = \"auto\"") != std::string::npos);
  CHECK(ra[0].at("samples") == "200");  // the scored fit uses every sample
  CHECK(rb[0].at("validation").find("held out: 20 of 200 samples (10%)") != std::string::npos);
  CHECK(rb[0].at("samples") == "180");
  CHECK(ra[0].at("run_id") != rb[0].at("run_id"));
  // Above the threshold "auto" holds out the single fraction and says why.
  const std::string big = tmp / "big.csv";
  write_sample_csv(sample_stratified(*bp, ExperimentSettings::kAutoFoldsMaxSamples + 1, 4), big);
  std::string big_body = body;
  big_body.replace(big_body.find(csv), csv.size(), big);
  run_quiet(write_text(tmp / "c.toml", "[experiment]\n" + big_body), tmp / "c");
  const auto rc = read_results_csv(tmp / "c/results.csv");
  REQUIRE(rc.size() == 1);
  INFO(rc[0].at("validation"));
  CHECK(rc[0].at("validation").find("held out: 2000 of 20001 samples (10%; folds = \"auto\": more than 20000 valid "
                                    "samples), not fitted") != std::string::npos);
  CHECK(rc[0].at("samples") == "18001");
  CHECK(parse_plan("[experiment]\n" + body, tmp / "c.toml", {})
            .runs[0].identity["validation"]["folds"] == "auto");
  CHECK(!parse_plan(with(""), "cfg.toml", {}).runs[0].identity["validation"].contains("folds"));
}

TEST_CASE("kfold: a run reports the mean held-out error over folds and fits every sample") {
  ScratchDir tmp;
  const BrdfPtr bp = Catalogue::builtin().make("bluepaint");
  const std::string csv = tmp / "s.csv";
  write_sample_csv(sample_stratified(*bp, 300, 4), csv);
  const std::string cfg =
      "[experiment]\nseed = 5\nfolds = 3\nplots = false\nrender = false\nexport = false\nvalidation_pairs = 0\n"
      "[[brdf]]\nfile = \"" + csv + "\"\n[sampling]\nkind = \"measured\"\n"
      "[[method]]\nkind = \"mccool\"\ntexture_size = 6\n"
      "[[method]]\nkind = \"svd\"\nterms = 1\ntexture_size = 6\n";
  run_quiet(write_text(tmp / "a.toml", cfg), tmp / "a");
  const auto rows = read_results_csv(tmp / "a/results.csv");
  REQUIRE(rows.size() == 2);
  for (const auto& r : rows) {
    INFO(r.at("method") << ": " << r.at("notes"));
    REQUIRE(r.at("status") == "ok");
    CHECK(r.at("samples") == "300");  // the scored fit uses every sample
    CHECK(r.at("validation").find("3-fold") != std::string::npos);
    const nlohmann::json rec =
        nlohmann::json::parse(read_text(tmp / ("a/runs/" + r.at("run_id") + "/run.json")));
    const auto& folds = rec.at("validation").at("folds");
    REQUIRE(folds.size() == 3);
    double mean = 0;
    size_t held = 0;
    for (const auto& f : folds) {
      mean += f.at("holdout_rel_mse").get<double>() / 3;
      held += f.at("held").get<size_t>();
      CHECK(f.at("train").get<size_t>() + f.at("held").get<size_t>() == 300);
    }
    CHECK(held == 300);
    CHECK(std::stod(r.at("holdout_rel_mse")) == Approx(mean).epsilon(1e-6));
  }
  // More folds than samples: the run fails naming the key.
  const std::string bad = cfg.substr(0, cfg.find("[[method]]\nkind = \"svd\"")) ;
  std::string t = bad;
  t.replace(t.find("folds = 3"), 9, "folds = 301");
  CHECK_THROWS_WITH(run_quiet(write_text(tmp / "b.toml", t), tmp / "b"),
                    Catch::Contains("experiment.folds") && Catch::Contains("found 301"));
  const auto rb = read_results_csv(tmp / "b/results.csv");
  REQUIRE(rb.size() == 1);
  CHECK(rb[0].at("status") == "failed");
  CHECK(rb[0].at("notes").find("experiment.folds") != std::string::npos);
  CHECK(rb[0].at("notes").find("300 valid") != std::string::npos);
}

TEST_CASE("kfold: per-channel rel_mse averages to rel_mse and isolates the channel in error") {
  const BrdfPtr bp = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_stratified(*bp, 200, 2);
  // The BRDF with its green channel doubled: only green is in error.
  class GreenTwice : public Brdf {
   public:
    explicit GreenTwice(BrdfPtr b) : b_(std::move(b)) {}
    Rgb eval(const Vec3& wi, const Vec3& wo) const override {
      Rgb v = b_->eval(wi, wo);
      v[1] *= 2;
      return v;
    }
    std::string name() const override { return "green-twice"; }
    std::string to_string() const override { return "green-twice"; }

   private:
    BrdfPtr b_;
  };
  const GreenTwice g(bp);
  const LogTransform lt = LogTransform::of(s);
  const auto ch = evaluate_metrics(g, s, lt).rel_mse_channel;
  CHECK(ch[0] == Approx(0.0).margin(1e-20));
  CHECK(ch[2] == Approx(0.0).margin(1e-20));
  CHECK(ch[1] > 0.1);
  CHECK((ch[0] + ch[1] + ch[2]) / 3 == Approx(evaluate_metrics(g, s, lt).rel_mse).epsilon(1e-9));
}
