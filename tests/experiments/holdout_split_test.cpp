// The held-out split (experiments/report/validation.h split_holdout) as a sample:
// over many seeds every valid sample, the first and the last included, is
// held out about `fraction` of the time; masked samples never are; weights
// follow their samples; held-out metrics use those weights.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "brdfs/sampleset.h"
#include "experiments/report/validation.h"

using namespace bf;

namespace {

// n samples whose red value is their index (so a held-out sample names its
// origin); samples 4, 11, ..., 53 are masked (negative green), weights 1 + index.
SampleSet indexed_set(int n) {
  SampleSet s;
  for (int k = 0; k < n; ++k) {
    const double phi = 0.1 * k;
    s.push(Vec3(0, 0, 1), Vec3(0.6 * std::cos(phi), 0.6 * std::sin(phi), 0.8),
           Rgb(double(k), k % 7 == 4 ? -1.0 : 1.0, 1.0), 1.0 + k);
  }
  s.validate();
  return s;
}

}  // namespace

TEST_CASE("validation: the held-out split holds out every valid sample, the last ones too, at the stated rate") {
  // 60 samples, 8 masked (indices 4, 11, ..., 53), 52 valid; fraction 0.1
  // holds out round(5.2) = 5 per seed. Over the 4000 seeds 1..4000 a uniform
  // choice holds each valid sample out 4000 * 5/52 = 384.6 times (binomial-like,
  // sd = sqrt(4000 * p (1 - p)) = 18.6, p = 5/52). Bound: every count within
  // 6 sd (112) of that, i.e. in [272, 497]. A shuffle that can never pick the
  // last valid sample gives it 0; one that always holds out the first
  // samples gives them 4000 and the rest 0. The seeds are fixed, so the test
  // is deterministic (measured: counts 344..429).
  const SampleSet s = indexed_set(60);
  const size_t n_valid = s.valid_count();
  REQUIRE(n_valid == 52);
  const int seeds = 4000;
  std::vector<int> count(60, 0);
  for (int seed = 1; seed <= seeds; ++seed) {
    const HoldoutSplit h = split_holdout(s, 0.1, static_cast<uint64_t>(seed));
    REQUIRE(h.held.size() == 5);
    REQUIRE(h.train.size() == 55);
    for (size_t k = 0; k < h.held.size(); ++k) {
      REQUIRE(h.held.valid[k] == 1);
      const int idx = static_cast<int>(h.held.value[k][0]);
      REQUIRE(idx >= 0);
      REQUIRE(idx < 60);
      ++count[idx];
    }
  }
  const double p = 5.0 / 52.0, expect = seeds * p, sd = std::sqrt(seeds * p * (1 - p));
  int lo = seeds, hi = 0;
  for (int k = 0; k < 60; ++k) {
    INFO("sample " << k << " held out " << count[k] << " times of " << seeds << " (expected " << expect
                   << " +- 6 x " << sd << ")");
    if (k % 7 == 4) {
      CHECK(count[k] == 0);  // masked: never held out
      continue;
    }
    CHECK(std::abs(count[k] - expect) <= 6 * sd);
    lo = std::min(lo, count[k]);
    hi = std::max(hi, count[k]);
  }
  INFO("counts of valid samples: " << lo << ".." << hi);
  CHECK(count[59] > 0);
  CHECK(count[58] > 0);
  CHECK(count[0] > 0);
}

TEST_CASE("validation: held-out samples keep their weights and are scored with them") {
  const SampleSet s = indexed_set(30);
  const HoldoutSplit h = split_holdout(s, 0.5, 11);
  REQUIRE(h.held.size() > 5);
  REQUIRE(h.held.weight.size() == h.held.size());
  REQUIRE(h.train.weight.size() == h.train.size());
  for (size_t k = 0; k < h.held.size(); ++k) {
    const int idx = static_cast<int>(h.held.value[k][0]);
    CHECK(h.held.weight[k] == 1.0 + idx);
    CHECK(h.held.wo[k] == s.wo[idx]);
  }
  for (size_t k = 0; k < h.train.size(); ++k) {
    const int idx = static_cast<int>(h.train.value[k][0]);
    CHECK(h.train.weight[k] == 1.0 + idx);
    CHECK(h.train.valid[k] == s.valid[idx]);
  }
  // holdout metrics: an approximation of value 2x the reference in red only,
  // green and blue exact, with unit values... red = index, so the error is
  // idx in red; lin_mae = sum_k w_k idx_k / (3 sum_k w_k) with w = 1 + idx.
  class TwiceRed : public Brdf {
   public:
    explicit TwiceRed(const SampleSet& s) : s_(s) {}
    Rgb eval(const Vec3& wi, const Vec3& wo) const override {
      for (size_t k = 0; k < s_.size(); ++k)
        if (s_.wi[k] == wi && s_.wo[k] == wo) return Rgb(2 * s_.value[k][0], s_.value[k][1], s_.value[k][2]);
      return Rgb::Zero();
    }
    std::string name() const override { return "twice-red"; }
    std::string to_string() const override { return "twice-red"; }

   private:
    const SampleSet& s_;
  };
  double num = 0, den = 0;
  for (size_t k = 0; k < h.held.size(); ++k) {
    if (!h.held.valid[k]) continue;
    const double idx = h.held.value[k][0], w = 1.0 + idx;
    num += w * idx;
    den += 3 * w;
  }
  const TwiceRed approx(s);
  const ValidationScores v = score_validation(approx, nullptr, &h.held, LogTransform::of(s));
  REQUIRE(v.holdout);
  CHECK(v.held.lin_mae == Approx(num / den).epsilon(1e-14));
}

TEST_CASE("validation: each validation column holds its own score") {
  // Distinct numbers everywhere, so a column filled from the wrong score shows.
  ValidationScores v;
  v.domain = true;
  v.val.rel_mse = 0.011;
  v.val.cos_rmse = 0.022;
  v.max_ratio = 3.5;
  v.holdout = true;
  v.held.rel_mse = 0.033;
  v.held.cos_rmse = 0.044;
  Row row;
  std::vector<std::string> notes;
  fill_validation_columns(v, 0.01, "scheme words", row, notes);
  CHECK(row.at("val_rel_mse") == format_number(0.011));
  CHECK(row.at("val_cos_rmse") == format_number(0.022));
  CHECK(row.at("val_max_ratio") == format_number(3.5));
  CHECK(row.at("holdout_rel_mse") == format_number(0.033));
  CHECK(row.at("holdout_cos_rmse") == format_number(0.044));
  CHECK(row.at("validation") == "scheme words");
  CHECK(row.at("flag").empty());  // 0.033 < 10 x 0.01 and < 0.05; ratio 3.5 < 10
  CHECK(notes.empty());
}
