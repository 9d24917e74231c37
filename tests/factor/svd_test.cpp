// Tests of the SVD baseline (Kautz-McCool): Eckart-Young agreement of the
// stored factors, exact rank-1 reproduction of a separable BRDF, grid/texel
// plumbing in both parameterizations, log mode, rank selection by tolerance.
#include <cmath>
#include <random>

#include "brdfs/models.h"
#include "brdfs/sampleset.h"
#include "factor/metrics.h"
#include "factor/svd_baseline.h"
#include "test_common.h"

using namespace bf;

namespace {
// A non-separable glossy test BRDF: Lambert + a normalized Phong lobe about
// the mirror direction of wo, per-channel weights.
class GlossTest final : public Brdf {
 public:
  explicit GlossTest(double e = 20.0) : e_(e) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
    const Vec3 r(-wo.x(), -wo.y(), wo.z());
    const double c = std::max(0.0, r.dot(wi));
    const double lobe = (e_ + 2.0) / (2.0 * M_PI) * std::pow(c, e_);
    return Rgb(0.2, 0.3, 0.1) / M_PI + Rgb(0.5, 0.4, 0.6) * lobe;
  }
  std::string name() const override { return "gloss-test"; }
  std::string to_string() const override { return "gloss-test(e=" + std::to_string(e_) + ")"; }

 private:
  double e_;
};

// f = a(wi) b(wo) per channel: exactly separable (rank 1 in wiwo).
class SeparableTest final : public Brdf {
 public:
  static Rgb a(const Vec3& w) { return Rgb(1.0 + 0.5 * w.x(), 0.7 + w.z() * w.z(), 2.0 - w.y()); }
  static Rgb b(const Vec3& w) { return Rgb(0.3 + w.z(), 1.0 + 0.2 * w.x() * w.y(), 0.5 + 0.4 * w.x()); }
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
    return a(wi) * b(wo);
  }
  std::string name() const override { return "separable-test"; }
  std::string to_string() const override { return "separable-test"; }
  bool reciprocal() const override { return false; }
  bool isotropic() const override { return false; }
};

Eigen::MatrixXd factor_reconstruction(const SvdFactorization& f, int c) {
  return f.U(c) * f.singular_values(c).head(f.rank()).asDiagonal() * f.V(c).transpose();
}
}  // namespace

TEST_CASE("svd: rank-K matrix error equals Eckart-Young (wiwo and halfdiff)") {
  const GlossTest brdf;
  for (auto param : {Parameterization::WiWo, Parameterization::HalfDiff}) {
    SvdOptions opt;
    opt.param = param;
    opt.res = 12;
    opt.rank = 6;
    const SvdTable table = tabulate_svd(brdf, opt);
    REQUIRE(table.M[0].rows() == Eigen::Index(table.grid.count()));
    const auto full = fit_svd(table, opt);
    for (int K : {1, 2, 4, 6}) {
      const auto f = full->truncated(K);
      for (int c = 0; c < 3; ++c) {
        const double err = (table.M[c] - factor_reconstruction(*f, c)).norm();
        const double ey = f->discarded_norm(c);
        INFO(to_string(param) << " K=" << K << " channel " << c << ": |M - M_K| = " << err
                              << ", Eckart-Young " << ey);
        REQUIRE(ey > 1e-6 * table.M[c].norm());  // a real tail, not rounding
        CHECK(std::abs(err - ey) <= 1e-9 * ey);
      }
    }
  }
}

TEST_CASE("svd: eval at grid nodes reads the rank-K matrix (texel plumbing)") {
  const GlossTest brdf;
  for (auto param : {Parameterization::WiWo, Parameterization::HalfDiff}) {
    SvdOptions opt;
    opt.param = param;
    opt.res = 10;
    opt.rank = 3;
    const SvdTable table = tabulate_svd(brdf, opt);
    const auto f = fit_svd(table, opt);
    std::array<Eigen::MatrixXd, 3> MK;
    for (int c = 0; c < 3; ++c) MK[c] = factor_reconstruction(*f, c);
    const DiskGrid& g = table.grid;
    int checked = 0;
    for (size_t r = 0; r < g.count(); r += 3)
      for (size_t c = 0; c < g.count(); c += 5) {
        // Interior nodes only (rim texels are evaluated at pulled-in points).
        const double rmax = 1.0 - opt.effective_rim_inset();
        if (g.point(g.texels[r]).norm() > rmax || g.point(g.texels[c]).norm() > rmax) continue;
        Vec3 wi = g.direction(g.texels[r], opt.effective_rim_inset()), wo = g.direction(g.texels[c], opt.effective_rim_inset());
        if (param == Parameterization::HalfDiff) {
          const Vec3 h = wi, d = wo;
          half_diff_inverse(h, d, wi, wo);
          if (wi.z() <= 0.0 || wo.z() <= 0.0) continue;
        }
        const Rgb v = f->eval_raw(wi, wo);
        for (int ch = 0; ch < 3; ++ch) CHECK(std::abs(v[ch] - MK[ch](r, c)) < 1e-11);
        ++checked;
      }
    CHECK(checked > 20);
  }
}

TEST_CASE("svd: a separable BRDF is reproduced at rank 1 at the grid nodes") {
  const SeparableTest brdf;
  SvdOptions opt;
  opt.res = 16;
  opt.rank = 1;
  const auto f = fit_svd(brdf, opt);
  CHECK(f->negative_texels() == 0);  // Perron vectors of a positive matrix
  const DiskGrid& g = f->grid();
  double worst = 0.0;
  for (int r : g.texels)
    for (int c : g.texels) {
      const double rmax = 1.0 - opt.effective_rim_inset();  // rim nodes read pulled-in values
      if (g.point(r).norm() > rmax || g.point(c).norm() > rmax) continue;
      const Vec3 wi = g.direction(r, opt.effective_rim_inset()), wo = g.direction(c, opt.effective_rim_inset());
      const Rgb exact = brdf.eval(wi, wo), got = f->eval(wi, wo);
      worst = std::max(worst, ((got - exact).abs() / exact.abs().max(1e-300)).maxCoeff());
    }
  INFO("max relative error at the nodes: " << worst);
  CHECK(worst < 1e-12);
  for (int c = 0; c < 3; ++c) CHECK(f->singular_values(c)[1] < 1e-12 * f->singular_values(c)[0]);
}

TEST_CASE("svd: log mode, negative texels, storage, truncation, description") {
  const GlossTest brdf(8.0);
  SvdOptions opt;
  opt.res = 10;
  opt.rank = 4;
  const auto lin = fit_svd(brdf, opt);
  CHECK(lin->negative_texels() > 0);  // higher terms change sign
  const size_t n = lin->grid().count();
  CHECK(lin->storage_floats() == 4 * 2 * n * 3 + 3 * 4);
  // truncated(k) is the rank-k fit.
  opt.rank = 2;
  const auto two = fit_svd(brdf, opt);
  const auto t2 = lin->truncated(2);
  const Vec3 wi = Vec3(0.3, 0.1, 0.9).normalized(), wo = Vec3(-0.2, 0.4, 0.8).normalized();
  CHECK(((two->eval(wi, wo) - t2->eval(wi, wo)).abs() < 1e-12).all());
  // Log mode: positive, finite, error falls with rank on a common sample set.
  opt.log = true;
  opt.rank = 4;
  const auto lg = fit_svd(brdf, opt);
  CHECK(lg->storage_floats() == 4 * 2 * n * 3 + 3 * 4 + 4);
  const SampleSet s = sample_grid(brdf, 8);
  const LogTransform lt = LogTransform::of(s);
  double prev = 1e300;
  for (int k = 1; k <= 4; ++k) {
    const Metrics m = evaluate_metrics(*lg->truncated(k), s, lt);
    INFO("log rank " << k << ": rel_mse " << m.rel_mse);
    CHECK(std::isfinite(m.rel_mse));
    CHECK(m.rel_mse <= prev * (1 + 1e-9));
    prev = m.rel_mse;
  }
  const nlohmann::json j = lg->describe();
  CHECK(j["method"] == "svd");
  CHECK(j["rank"] == 4);
  CHECK(j["log"] == true);
  CHECK(j["sigma"].size() == 3);
  CHECK(j.contains("negative_texels"));
  // Texture accessors place the factors on the full grid.
  const std::vector<double> u0 = lin->row_texture(0, 0);
  REQUIRE(u0.size() == size_t(10 * 10));
  CHECK(u0[lin->grid().texels[5]] == lin->U(0)(5, 0));
}

TEST_CASE("svd: a Lambertian BRDF is exact at rank 1 everywhere, log mode too") {
  LambertParams lp;
  lp.kd = Rgb(0.2, 0.5, 0.8);
  const Lambert brdf(lp);
  for (bool log : {false, true}) {
    SvdOptions opt;
    opt.res = 6;
    opt.log = log;
    const auto f = fit_svd(brdf, opt);
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int k = 0; k < 200; ++k) {
      const Vec3 wi = Vec3(U(rng), U(rng), 1.0 + U(rng)).normalized();
      const Vec3 wo = Vec3(U(rng), U(rng), 1.0 + U(rng)).normalized();
      if (wi.z() <= 0 || wo.z() <= 0) continue;
      const double tol = log ? 1.5e-5 : 1e-12;  // log mode: A exp(log(1 + eps)) = f (1 + eps)
      CHECK(((f->eval(wi, wo) - brdf.eval(wi, wo)).abs() <= tol * brdf.eval(wi, wo)).all());
    }
  }
}

TEST_CASE("svd: rank selection stops at the smallest rank under the tolerance") {
  const GlossTest brdf(8.0);
  const SampleSet s = sample_grid(brdf, 8);
  SvdOptions opt;
  opt.res = 10;
  // Errors of every rank, to know the answer.
  const auto full = fit_svd(brdf, [&] { SvdOptions o = opt; o.rank = 6; return o; }());
  const LogTransform lt = LogTransform::of(s);
  std::vector<double> err;
  for (int k = 1; k <= 6; ++k) err.push_back(evaluate_metrics(*full->truncated(k), s, lt).cos_rmse);
  const double tol = 0.5 * (err[1] + err[2]);  // between rank 2 and rank 3 (if decreasing)
  const SizeChoice ch = select_svd_rank(brdf, s, opt, {"cos_rmse", tol}, 6);
  int expect = 0;
  for (int k = 1; k <= 6 && !expect; ++k)
    if (err[k - 1] <= tol) expect = k;
  INFO("errors " << err[0] << " " << err[1] << " " << err[2] << " " << err[3]);
  CHECK(ch.reached);
  CHECK(ch.value == expect);
  CHECK(ch.error == Approx(err[expect - 1]).epsilon(1e-12));
  CHECK(ch.tried.size() == size_t(expect));
  CHECK(ch.seconds > 0.0);
  REQUIRE(ch.result);
  CHECK(ch.result->method() == "svd");
  // Unreachable tolerance: the best rank up to the cap, reached = false.
  const SizeChoice none = select_svd_rank(brdf, s, opt, {"cos_rmse", 1e-12}, 3);
  CHECK_FALSE(none.reached);
  CHECK(none.tried.size() == 3);
}

TEST_CASE("svd: invalid options name the field") {
  const GlossTest brdf;
  SvdOptions opt;
  opt.res = 1;
  REQUIRE_THROWS_WITH(fit_svd(brdf, opt), Catch::Contains("texture_size: expected 2..256, found 1"));
  opt = SvdOptions();
  opt.rank = 0;
  REQUIRE_THROWS_WITH(fit_svd(brdf, opt), Catch::Contains("terms: expected >= 1"));
  opt = SvdOptions();
  opt.subtract_eps = true;
  REQUIRE_THROWS_WITH(fit_svd(brdf, opt), Catch::Contains("subtract_eps applies only"));
  REQUIRE_THROWS_WITH(select_svd_rank(brdf, sample_grid(brdf, 4), SvdOptions(), {"rmse", 0.1}, 2),
                      Catch::Contains("expected one of"));
  REQUIRE_THROWS_WITH(select_svd_rank(brdf, sample_grid(brdf, 4), SvdOptions(), {"cos_rmse", 0.0}, 2),
                      Catch::Contains("value: expected a finite number > 0"));
}

TEST_CASE("svd: halfdiff pairs below the horizon are extended, not zeroed") {
  // The zero fill puts a jump (log(eps) in log mode) inside the table that a
  // low-rank SVD smears over valid texels; the lifted extension does not.
  const GlossTest brdf(8.0);
  const SampleSet s = sample_grid(brdf, 8);
  const LogTransform lt = LogTransform::of(s);
  double err[2];
  for (bool ext : {false, true}) {
    SvdOptions opt;
    opt.param = Parameterization::HalfDiff;
    opt.res = 12;
    opt.rank = 3;
    opt.log = true;
    opt.extend_below_horizon = ext;
    err[ext] = evaluate_metrics(*fit_svd(brdf, opt), s, lt).rel_mse;
  }
  INFO("rel_mse zero fill " << err[0] << ", extended " << err[1]);
  CHECK(err[1] < 0.5 * err[0]);
}

TEST_CASE("svd: Cook-Torrance stays bounded at the rim (grazing texels, issue #7)") {
  // cole-cook-torrance: F D G / (4 cos_i cos_o) reaches ~1e7 at theta 89.99 deg
  // in the mirror configuration. Rim texels tabulated there (the old inset
  // 1e-4) made the linear SVD reproduce that spike and bilinear lookups spread
  // it over the outer cells: lin_max ~5e4 for a BRDF peaking ~140 on the
  // samples. Rim texels now take the value half a texel in.
  CookTorranceParams cp;
  cp.kd = Rgb::Constant(0.1);
  cp.ks = Rgb::Constant(0.9);
  cp.m = 0.3;
  cp.f0 = Rgb::Constant(0.1);
  const CookTorrance brdf(cp);
  const SampleSet s = sample_stratified(brdf, 4000, 5);
  const LogTransform lt = LogTransform::of(s);
  double fmax = 0.0;
  for (size_t k = 0; k < s.size(); ++k)
    if (s.valid[k]) fmax = std::max(fmax, s.value[k].maxCoeff());
  const auto approx_max = [&](const SvdFactorization& f) {
    double m = 0.0;
    for (size_t k = 0; k < s.size(); ++k)
      if (s.valid[k]) m = std::max(m, f.eval(s.wi[k], s.wo[k]).abs().maxCoeff());
    return m;
  };
  for (auto param : {Parameterization::WiWo, Parameterization::HalfDiff})
    for (bool log : {false, true}) {
      SvdOptions opt;
      opt.param = param;
      opt.res = 12;
      opt.rank = 4;
      opt.log = log;
      const auto f = fit_svd(brdf, opt);
      const double amax = approx_max(*f);
      const double rel = evaluate_metrics(*f, s, lt).rel_mse;
      INFO(to_string(param) << (log ? " log" : " linear") << ": max |approx| " << amax << ", BRDF max " << fmax
                            << ", rel_mse " << rel);
      CHECK(amax <= 2.0 * fmax);
      CHECK(std::isfinite(rel));
      if (!log) {
        // The mechanism: the old inset tabulates the grazing spike.
        opt.rim_inset = 1e-4;
        const auto old = fit_svd(brdf, opt);
        const double old_max = approx_max(*old), old_rel = evaluate_metrics(*old, s, lt).rel_mse;
        INFO("rim_inset 1e-4: max |approx| " << old_max << ", rel_mse " << old_rel);
        CHECK(old_max > 10.0 * fmax);
        CHECK(rel < 0.5 * old_rel);
      }
    }
}
