// Metrics against hand-computed closed forms where the easy shortcuts give
// other numbers: unequal (and zero) sample weights, a masked sample, the
// unweighted mean A of the log transform, and val_max_ratio's per-channel peak
// on BRDFs whose brightest channel is green or blue (docs/design.md §4).
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "brdfs/sampleset.h"
#include "factor/metrics.h"

using namespace bf;

namespace {

// A BRDF given by a table: its value at the listed (wi, wo) pairs, 0 elsewhere.
class TableBrdf : public Brdf {
 public:
  void add(const Vec3& wi, const Vec3& wo, const Rgb& v) { rows_.push_back({wi, wo, v}); }
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    for (const Row& r : rows_)
      if (r.wi == wi && r.wo == wo) return r.v;
    return Rgb::Zero();
  }
  std::string name() const override { return "table"; }
  std::string to_string() const override { return "table"; }

 private:
  struct Row {
    Vec3 wi, wo;
    Rgb v;
  };
  std::vector<Row> rows_;
};

}  // namespace

TEST_CASE("metrics: unequal sample weights give the weighted closed form of every weighted metric") {
  // Three valid samples and a masked one:
  //   k  cos_i  weight  f          approximation   error f^ - f
  //   0  0.6    1       (1, 1, 1)  (0.5, 1, 1)     (-0.5, 0, 0)
  //   1  0.8    3       (1, 1, 1)  (1, 1, 4)       (0, 0, 3)
  //   2  1.0    0       (1, 1, 1)  (1, 9, 1)       (0, 8, 0)   weight 0: only the max metrics see it
  //   3  below the horizon (masked), weight 5, approximation 100: never scored
  // W = 3 (1 + 3 + 0) = 12.
  //   lin_rmse = sqrt((1 * 0.5^2 + 3 * 3^2) / 12) = sqrt(27.25 / 12)
  //   lin_mae  = (1 * 0.5 + 3 * 3) / 12 = 9.5 / 12   (|error|: signed it would be 8.5 / 12)
  //   lin_max  = 8
  //   cos_rmse = sqrt((1 * (0.5 * 0.6)^2 + 3 * (3 * 0.8)^2) / 12) = sqrt(17.37 / 12)
  // A = (1, 1, 1) (the mean of the valid samples), so with e = eps
  //   rel_mse = (1 * ln((0.5 + e)/(1 + e))^2 + 3 * ln((4 + e)/(1 + e))^2) / 12
  //   rel_mae = (1 * |ln((0.5 + e)/(1 + e))| + 3 * ln((4 + e)/(1 + e))) / 12
  //   rel_max = ln((9 + e)/(1 + e)).
  // With every weight ignored (taken as 1) the same data give lin_rmse
  // sqrt(73.25 / 9), lin_mae 11.5 / 9, cos_rmse sqrt(69.85 / 9): all different.
  const Vec3 wi0(0.8, 0.0, 0.6), wi1(0.0, 0.6, 0.8), wi2(0.0, 0.0, 1.0), wi3(0.6, 0.0, -0.8);
  const Vec3 wo0(0.0, 0.0, 1.0), wo1(0.6, 0.0, 0.8), wo2(0.0, 0.8, 0.6), wo3(0.0, 0.0, 1.0);
  SampleSet s;
  s.push(wi0, wo0, Rgb(1, 1, 1), 1.0);
  s.push(wi1, wo1, Rgb(1, 1, 1), 3.0);
  s.push(wi2, wo2, Rgb(1, 1, 1), 0.0);
  s.push(wi3, wo3, Rgb(1, 1, 1), 5.0);
  s.validate();
  REQUIRE(s.valid_count() == 3);
  REQUIRE(s.invalid_horizon == 1);
  TableBrdf approx;
  approx.add(wi0, wo0, Rgb(0.5, 1, 1));
  approx.add(wi1, wo1, Rgb(1, 1, 4));
  approx.add(wi2, wo2, Rgb(1, 9, 1));
  approx.add(wi3, wo3, Rgb(100, 100, 100));
  const double e = 1e-5;
  const LogTransform t = LogTransform::of(s, e);
  for (int c = 0; c < 3; ++c) CHECK(t.A[c] == 1.0);
  const Metrics m = evaluate_metrics(approx, s, t);
  CHECK(m.samples == 3);
  CHECK(m.lin_rmse == Approx(std::sqrt(27.25 / 12.0)).epsilon(1e-14));
  CHECK(m.lin_mae == Approx(9.5 / 12.0).epsilon(1e-14));
  CHECK(m.lin_max == 8.0);
  CHECK(m.cos_rmse == Approx(std::sqrt(17.37 / 12.0)).epsilon(1e-14));
  const double gh = std::log((0.5 + e) / (1 + e)), g4 = std::log((4 + e) / (1 + e)), g9 = std::log((9 + e) / (1 + e));
  CHECK(m.rel_mse == Approx((gh * gh + 3 * g4 * g4) / 12.0).epsilon(1e-13));
  CHECK(m.rel_mae == Approx((-gh + 3 * g4) / 12.0).epsilon(1e-13));
  CHECK(m.rel_max == Approx(g9).epsilon(1e-13));

  // Scaling every weight by the same factor changes nothing (W scales too).
  SampleSet s2 = s;
  for (double& w : s2.weight) w *= 0.25;
  const Metrics m2 = evaluate_metrics(approx, s2, t);
  CHECK(m2.lin_rmse == Approx(m.lin_rmse).epsilon(1e-14));
  CHECK(m2.rel_mse == Approx(m.rel_mse).epsilon(1e-14));
  CHECK(m2.cos_rmse == Approx(m.cos_rmse).epsilon(1e-14));
}

TEST_CASE("metrics: the log transform's A is the unweighted mean of the valid samples") {
  // Values 1 and 3 with weights 1 and 3: unweighted mean 2 (the weighted one
  // would be 2.5); a masked sample of value 100 is not part of it. Per channel
  // values differ so a channel mix-up shows.
  SampleSet s;
  s.push(Vec3(0, 0, 1), Vec3(0, 0, 1), Rgb(1, 2, 4), 1.0);
  s.push(Vec3(0.6, 0, 0.8), Vec3(0, 0, 1), Rgb(3, 6, 8), 3.0);
  s.push(Vec3(0.6, 0, -0.8), Vec3(0, 0, 1), Rgb(100, 100, 100), 1.0);
  s.validate();
  REQUIRE(s.valid_count() == 2);
  const LogTransform t = LogTransform::of(s, 1e-3);
  CHECK(t.A[0] == 2.0);
  CHECK(t.A[1] == 4.0);
  CHECK(t.A[2] == 6.0);
  CHECK(t.eps == 1e-3);
  CHECK(t.g(1, 4.0) == Approx(std::log((4.0 + 1e-3 * 4.0) / 4.0)).epsilon(1e-15));
}

TEST_CASE("metrics: val_max_ratio divides each channel by its own peak when green or blue is brightest") {
  // Green-dominant: f = (0.1, 2, 0.5) and (0.2, 1, 0.4); peaks (0.2, 2, 0.5).
  // Approximation (0.1, 3, 0.5) and (0.2, 1, 0.4): ratios (0.5, 1.5, 1) and
  // (1, 0.5, 0.8), so the ratio is 1.5 (green's 3 / 2). Dividing every channel
  // by red's peak would give 3 / 0.2 = 15; by the largest peak, 0.2 / 2.
  // A masked sample (below the horizon) with green 50 is neither a peak nor scored.
  const Vec3 a(0, 0, 1), b(0.6, 0, 0.8), below(0.6, 0, -0.8);
  {
    SampleSet s;
    s.push(a, a, Rgb(0.1, 2.0, 0.5));
    s.push(b, a, Rgb(0.2, 1.0, 0.4));
    s.push(below, a, Rgb(0.0, 50.0, 0.0));
    s.validate();
    REQUIRE(s.valid_count() == 2);
    TableBrdf approx;
    approx.add(a, a, Rgb(0.1, 3.0, 0.5));
    approx.add(b, a, Rgb(0.2, 1.0, 0.4));
    approx.add(below, a, Rgb(0.0, 500.0, 0.0));
    CHECK(peak_ratio(approx, s) == Approx(1.5).epsilon(1e-15));
  }
  // Blue-dominant: f = (0.1, 0.2, 4) and (0.2, 0.1, 1); peaks (0.2, 0.2, 4).
  // Approximation (0.1, 0.2, 6) and (0.1, 0.1, 1): ratios (0.5, 1, 1.5) and
  // (0.5, 0.5, 0.25): 1.5 (red's peak would give 6 / 0.2 = 30).
  {
    SampleSet s;
    s.push(a, a, Rgb(0.1, 0.2, 4.0));
    s.push(b, a, Rgb(0.2, 0.1, 1.0));
    s.validate();
    TableBrdf approx;
    approx.add(a, a, Rgb(0.1, 0.2, 6.0));
    approx.add(b, a, Rgb(0.1, 0.1, 1.0));
    CHECK(peak_ratio(approx, s) == Approx(1.5).epsilon(1e-15));
  }
  // A channel that is 0 on every valid sample is skipped (no peak), whatever
  // the approximation puts there; a negative approximation counts as 0.
  {
    SampleSet s;
    s.push(a, a, Rgb(0.0, 0.5, 2.0));
    s.push(b, a, Rgb(0.0, 1.0, 1.0));
    s.validate();
    TableBrdf approx;
    approx.add(a, a, Rgb(7.0, -3.0, 1.0));
    approx.add(b, a, Rgb(7.0, 0.8, 1.0));
    CHECK(peak_ratio(approx, s) == Approx(0.8).epsilon(1e-15));
  }
}
