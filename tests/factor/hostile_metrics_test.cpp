// Metrics on hostile magnitudes (issue #8): a BRDF scaled by 1e200 or 1e-300
// (or subnormal) must score its true error, not saturate at the cap or
// underflow to 0; a non-finite approximation is charged the documented cap.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <limits>

#include "brdfs/sampleset.h"
#include "factor/metrics.h"

using namespace bf;

namespace {

// A BRDF given by a function of (wi, wo), times a scale.
class FnBrdf : public Brdf {
 public:
  FnBrdf(std::function<double(const Vec3&, const Vec3&)> f, double scale) : f_(std::move(f)), scale_(scale) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    const double v = scale_ * f_(wi, wo);
    return Rgb(v, 0.5 * v, 2.0 * v);
  }
  std::string name() const override { return "fn"; }
  std::string to_string() const override { return "fn"; }

 private:
  std::function<double(const Vec3&, const Vec3&)> f_;
  double scale_;
};

// Samples with wi at cos(theta_i) = 0.6 and a few outgoing directions.
SampleSet directions_at_cos06() {
  SampleSet s;
  const Vec3 wi(0.8, 0.0, 0.6);
  for (const Vec3& wo : {Vec3(0, 0, 1), Vec3(0.6, 0, 0.8), Vec3(0, -0.8, 0.6), Vec3(0, 0.6, 0.8)})
    s.push(wi, wo, Rgb::Zero());
  s.validate();
  return s;
}

}  // namespace

TEST_CASE("metrics: constant BRDFs scaled by 1e200, 1e-300 and a subnormal score their exact error") {
  // Reference s * (1, 0.5, 2), approximation 1.5 times that: the channel errors
  // are s * (0.5, 0.25, 1), so lin_rmse = s sqrt((0.25 + 0.0625 + 1) / 3),
  // lin_mae = s (1.75 / 3), lin_max = s, cos_rmse = 0.6 lin_rmse (cos theta_i =
  // 0.6 everywhere); in log space every channel's error is log((1.5 + eps) / (1 + eps)).
  for (const double scale : {1.0, 1e200, 1e-300, 1e-315}) {
    INFO("scale " << scale);
    SampleSet s = directions_at_cos06();
    const FnBrdf ref([](const Vec3&, const Vec3&) { return 1.0; }, scale);
    const FnBrdf approx([](const Vec3&, const Vec3&) { return 1.5; }, scale);
    evaluate_into(ref, s);
    s.validate();
    REQUIRE(s.valid_count() == 4);
    const LogTransform t = LogTransform::of(s, 1e-5);
    const Metrics m = evaluate_metrics(approx, s, t);
    // The exact errors of the doubles actually stored (for a subnormal scale the
    // stored values are not exactly 1 and 1.5 times the scale).
    double sq = 0, ab = 0, mx = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = approx.eval(s.wi[0], s.wo[0])[c] - s.value[0][c];  // exact (same binade)
      const double rel = d / scale;                                          // in [0.25, 1]
      sq += rel * rel;
      ab += rel;
      mx = std::max(mx, rel);
    }
    // A subnormal near 1e-315 carries about 28 significant bits.
    const double tol = scale < std::numeric_limits<double>::min() ? 1e-7 : 1e-13;
    CHECK(m.lin_rmse == Approx(scale * std::sqrt(sq / 3)).epsilon(tol));
    CHECK(m.lin_mae == Approx(scale * (ab / 3)).epsilon(tol));
    CHECK(m.lin_max == Approx(scale * mx).epsilon(tol));
    CHECK(m.cos_rmse == Approx(0.6 * scale * std::sqrt(sq / 3)).epsilon(tol));
    CHECK(m.lin_rmse > 0);
    if (scale >= std::numeric_limits<double>::min()) {
      const double dg = std::log((1.5 + 1e-5) / (1.0 + 1e-5));
      CHECK(m.rel_mse == Approx(dg * dg).epsilon(1e-9));
      CHECK(m.rel_mae == Approx(dg).epsilon(1e-9));
      CHECK(m.rel_max == Approx(dg).epsilon(1e-9));
    }
  }
}

TEST_CASE("metrics: scaling reference and approximation by s scales the linear metrics by s") {
  const auto a = [](const Vec3& wi, const Vec3& wo) { return 1.0 + 3.0 * wi.z() * wo.z() + wo.x() * wo.x(); };
  const auto b = [](const Vec3& wi, const Vec3& wo) { return 1.2 + 2.0 * wi.z() + 0.5 * wo.y(); };
  const SampleSet base = sample_stratified(FnBrdf(a, 1.0), 500, 7);
  const LogTransform t1 = LogTransform::of(base, 1e-5);
  const Metrics m1 = evaluate_metrics(FnBrdf(b, 1.0), base, t1);
  REQUIRE(m1.lin_rmse > 0.1);
  for (const double scale : {1e200, 1e-300}) {
    INFO("scale " << scale);
    SampleSet s = base;
    evaluate_into(FnBrdf(a, scale), s);
    s.validate();
    REQUIRE(s.valid_count() == base.valid_count());
    const Metrics m = evaluate_metrics(FnBrdf(b, scale), s, LogTransform::of(s, 1e-5));
    CHECK(m.lin_rmse == Approx(scale * m1.lin_rmse).epsilon(1e-12));
    CHECK(m.lin_mae == Approx(scale * m1.lin_mae).epsilon(1e-12));
    CHECK(m.lin_max == Approx(scale * m1.lin_max).epsilon(1e-12));
    CHECK(m.cos_rmse == Approx(scale * m1.cos_rmse).epsilon(1e-12));
    // Log-space metrics do not depend on the scale (A scales with f).
    CHECK(m.rel_mse == Approx(m1.rel_mse).epsilon(1e-9));
    CHECK(m.rel_max == Approx(m1.rel_max).epsilon(1e-9));
  }
}

TEST_CASE("metrics: a non-finite approximation is charged the cap 1e300, never NaN or Inf") {
  SampleSet s = directions_at_cos06();
  evaluate_into(FnBrdf([](const Vec3&, const Vec3&) { return 1.0; }, 1.0), s);
  s.validate();
  const LogTransform t = LogTransform::of(s, 1e-5);
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    const Metrics m = evaluate_metrics(FnBrdf([bad](const Vec3&, const Vec3&) { return bad; }, 1.0), s, t);
    for (const char* name : {"rel_mse", "rel_mae", "rel_max", "lin_rmse", "lin_mae", "lin_max", "cos_rmse"}) {
      INFO(name << " for " << bad);
      CHECK(metric_value(m, name) == 1e300);
    }
  }
  // A finite approximation 1e307 against 1 (channels 1e307, 5e306, 2e307): the
  // linear errors exceed the cap, the log errors are log(1e307 + eps) - log(1 + eps).
  const Metrics m = evaluate_metrics(FnBrdf([](const Vec3&, const Vec3&) { return 1e307; }, 1.0), s, t);
  CHECK(m.lin_max == 1e300);
  CHECK(m.lin_rmse == 1e300);
  const double dg = std::log(1e307 + 1e-5) - std::log(1 + 1e-5);
  CHECK(m.rel_max == Approx(dg).epsilon(1e-12));
  CHECK(m.rel_mse == Approx(dg * dg).epsilon(1e-12));
}
