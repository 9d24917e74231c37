// Tests of the structure analysis and the structured search on planted
// product BRDFs (f = exp(a(P1 x) + b(P2 x) [+ c(P3 x')])): the search must end
// near the floor, the error of `fit` at the true projections.
#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "brdfs/catalogue.h"
#include "brdfs/sampleset.h"
#include "factor/export.h"
#include "factor/metrics.h"
#include "search/planted.h"
#include "search/structure.h"
#include "search/term_search.h"
#include "test_common.h"

using namespace bf;

namespace {

// The floor: fit at the true projections, best order of the terms.
double floor_error(const PlantedProductBrdf& b, const FitData& d, int res) {
  std::vector<TermSpec> t = b.specs(res);
  std::vector<size_t> order(t.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  double best = 1e300;
  do {
    std::vector<TermSpec> s;
    for (size_t i : order) s.push_back(t[i]);
    std::vector<double> e;
    fit_homomorphic(d, s, FitOptions{}, "fit", &e);
    best = std::min(best, e.back());
  } while (std::next_permutation(order.begin(), order.end()));
  return best;
}

// The joint floor: fit at the true projections with every term solved jointly.
double joint_floor_error(const PlantedProductBrdf& b, const FitData& d, int res) {
  FitOptions fo;
  fo.solve_last = static_cast<int>(b.terms().size());
  std::vector<double> e;
  fit_homomorphic(d, b.specs(res), fo, "fit", &e);
  return e.back();
}

Mat24 plane_of(const Rotation4& R) { return R.projection(Parameterization::WiWo, 8).P; }

SearchOptions structured(int terms, int texture) {
  SearchOptions opt;
  opt.strategy = "structured";
  opt.terms = terms;
  opt.texture_size = texture;
  return opt;
}

// Mixed planted member `member` with `terms` terms (main parameterization p),
// 16^4 grid, texture 16, search seed `seed`: the structured search ends within `bar`
// times the joint floor with every found plane within `plane_tol` (plane
// distance) of a true plane of its parameterization.
SearchResult check_mixed_member(int member, int terms, Parameterization p, double bar, double plane_tol,
                                unsigned seed = 1) {
  const PlantedProductBrdf b = planted_rotation_brdf(member, terms, p);
  const SampleSet s = sample_grid(b, 16);
  const FitData d(s, 1e-5);
  const double fl = joint_floor_error(b, d, 16);
  SearchOptions opt = structured(terms, 16);
  opt.seed = seed;
  SearchResult r = search_factorization(d, opt);
  INFO(b.to_string() << ": joint floor " << fl << ", structured " << r.rel_mse_after_term.back() << " ("
                     << r.evaluations << " fits)");
  CHECK(r.rel_mse_after_term.back() <= bar * fl);
  REQUIRE(r.factorization->terms().size() == static_cast<size_t>(terms));
  for (const FactorTerm& t : r.factorization->terms()) {
    const double dist = b.nearest_plane_distance(t.proj.param, t.proj.P);
    INFO(to_string(t.proj.param) << " term, distance to the nearest true plane " << dist);
    CHECK(dist < plane_tol);
  }
  return r;
}

// The number of r's terms read through wiwo.
int wiwo_terms(const SearchResult& r) {
  int n = 0;
  for (const FactorTerm& t : r.factorization->terms()) n += t.proj.param == Parameterization::WiWo;
  return n;
}

// Planted pair `member` (planted_mixed_pair_brdf, `first` first) on a grid^4
// grid: the 2-term structured search at `texture` ends within `bar` times the
// joint floor with one wiwo term and every plane within `plane_tol` of a true
// plane of its parameterization.
void check_pair(int member, Parameterization first, int grid, int texture, double bar, double plane_tol) {
  const PlantedProductBrdf b = planted_mixed_pair_brdf(member, first);
  REQUIRE(b.terms().size() == 2);
  CHECK(b.terms()[0].param == first);
  CHECK(b.terms()[1].param == other_parameterization(first));
  const SampleSet s = sample_grid(b, grid);
  const FitData d(s, 1e-5);
  const double fl = joint_floor_error(b, d, texture);
  const SearchResult r = search_factorization(d, structured(2, texture));
  INFO(b.to_string() << ": joint floor " << fl << ", structured " << r.rel_mse_after_term.back() << " ("
                     << r.evaluations << " fits)");
  CHECK(r.rel_mse_after_term.back() <= bar * fl);
  REQUIRE(r.factorization->terms().size() == 2);
  CHECK(wiwo_terms(r) == 1);
  for (const FactorTerm& t : r.factorization->terms()) {
    INFO(to_string(t.proj.param) << " term");
    CHECK(b.nearest_plane_distance(t.proj.param, t.proj.P) < plane_tol);
  }
}

}  // namespace

TEST_CASE("rotation4: from_matrix inverts matrix") {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 50; ++i) {
    const Rotation4 R = Rotation4::random(rng);
    const Rotation4 Q = Rotation4::from_matrix(R.matrix());
    INFO("rotation " << i);
    CHECK((Q.matrix() - R.matrix()).cwiseAbs().maxCoeff() < 1e-12);
    CHECK(Q.equal_up_to_sign(R, 1e-10));
  }
}

TEST_CASE("structure: local Hessians of a quadratic are its matrix") {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::Matrix4d A;
  for (int i = 0; i < 4; ++i)
    for (int j = i; j < 4; ++j) A(i, j) = A(j, i) = U(rng);
  const Vec4 b(U(rng), U(rng), U(rng), U(rng));
  std::vector<Vec4> x(20000);
  std::vector<double> y(x.size());
  for (size_t k = 0; k < x.size(); ++k) {
    x[k] = Vec4(U(rng), U(rng), U(rng), U(rng));
    y[k] = 0.5 * x[k].dot(A * x[k]) + b.dot(x[k]) + 3;
  }
  StructureOptions so;
  so.centres = 50;
  const auto hs = local_hessians(x, y, {}, so);
  REQUIRE(hs.size() >= 40);  // a few centres near the cube's corners may have too few neighbours
  for (const Eigen::Matrix4d& H : hs) CHECK((H - A).cwiseAbs().maxCoeff() < 1e-6);  // measured 6e-8
}

TEST_CASE("structure: one LocalHessians reads many functions - each call is a fresh estimate") {
  // The structured search builds one estimator per sample set and reads the
  // Hessians of every residual with it: a call must not depend on the calls
  // before it, and must equal local_hessians (the same neighbours, weights
  // and factorization) on weighted samples.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1, 1);
  std::vector<Vec4> x(12000);
  std::vector<double> w(x.size());
  for (size_t k = 0; k < x.size(); ++k) {
    x[k] = Vec4(U(rng), U(rng), U(rng), U(rng));
    w[k] = 0.5 + 0.5 * (U(rng) + 1);
  }
  StructureOptions so;
  so.centres = 40;
  so.radius = 0.5;
  so.seed = 3;
  const LocalHessians est(x, w, so);
  std::vector<Eigen::Matrix4d> A(3);
  std::vector<std::vector<double>> y(3, std::vector<double>(x.size()));
  for (int f = 0; f < 3; ++f) {
    for (int i = 0; i < 4; ++i)
      for (int j = i; j < 4; ++j) A[f](i, j) = A[f](j, i) = U(rng);
    for (size_t k = 0; k < x.size(); ++k) y[f][k] = 0.5 * x[k].dot(A[f] * x[k]) + x[k][f] - 2;
  }
  std::vector<std::vector<Eigen::Matrix4d>> first(3);
  for (int f : {0, 1, 2, 1, 0}) {
    const auto hs = est(y[f]);
    const auto fresh = local_hessians(x, y[f], w, so);
    REQUIRE(hs.size() == fresh.size());
    REQUIRE(hs.size() >= 30);
    for (size_t c = 0; c < hs.size(); ++c) {
      INFO("function " << f << ", centre " << c);
      CHECK(hs[c] == fresh[c]);                                 // bit for bit
      CHECK((hs[c] - A[f]).cwiseAbs().maxCoeff() < 1e-6);       // the quadratic's matrix
      if (!first[f].empty()) CHECK(hs[c] == first[f][c]);       // a repeat reads the same
    }
    if (first[f].empty()) first[f] = hs;
  }
  CHECK_THROWS_WITH(est(std::vector<double>(x.size() - 1)),
                    Catch::Contains("y has 11999 values, expected one per sample (12000)"));
}

TEST_CASE("structure: split_planes recovers the planes of block-diagonal Hessians") {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    const Rotation4 R = Rotation4::random(rng);
    const Eigen::Matrix4d Q = R.matrix();
    std::vector<Eigen::Matrix4d> hs;
    for (int k = 0; k < 200; ++k) {
      Eigen::Matrix4d B = Eigen::Matrix4d::Zero();
      B(0, 0) = 3 * U(rng), B(1, 1) = 3 * U(rng), B(0, 1) = B(1, 0) = U(rng);
      B(2, 2) = U(rng), B(3, 3) = U(rng), B(2, 3) = B(3, 2) = 0.5 * U(rng);
      hs.push_back(Q * B * Q.transpose());
    }
    const PlaneSplit s = split_planes(hs);
    Mat24 A, Bp;
    A << Q.col(0).transpose(), Q.col(1).transpose();
    Bp << Q.col(2).transpose(), Q.col(3).transpose();
    INFO("trial " << trial << ": off-block " << s.off_block << ", share of A " << s.share_a);
    // Plane A carries more curvature (3x the entries), so it comes first.
    CHECK(plane_distance(plane_of(s.first), A) < 1e-5);
    CHECK(plane_distance(plane_of(s.second), Bp) < 1e-5);
    CHECK(s.off_block < 1e-8);
    CHECK(s.share_a > 0.5);
  }
}

TEST_CASE("structure: split_planes separates planes whose curvatures are alike") {
  // Each Hessian comes with its twin whose blocks are swapped, so sum H^2 has
  // every eigenvalue twice, once per plane: its eigenvectors may mix the
  // planes arbitrarily, and no pairing of them is the true split. The
  // random combinations of the Hessians must find it.
  std::mt19937_64 rng(15);
  std::uniform_real_distribution<double> U(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    const Rotation4 R = Rotation4::random(rng);
    const Eigen::Matrix4d Q = R.matrix();
    std::vector<Eigen::Matrix4d> hs;
    for (int k = 0; k < 100; ++k) {
      Eigen::Matrix2d a, b;
      a << 2 * U(rng), U(rng), 0, U(rng);
      b << U(rng), 0.5 * U(rng), 0, 2 * U(rng);
      a(1, 0) = a(0, 1);
      b(1, 0) = b(0, 1);
      for (int twin = 0; twin < 2; ++twin) {
        Eigen::Matrix4d B = Eigen::Matrix4d::Zero();
        B.block<2, 2>(0, 0) = twin ? b : a;
        B.block<2, 2>(2, 2) = twin ? a : b;
        hs.push_back(Q * B * Q.transpose());
      }
    }
    const PlaneSplit s = split_planes(hs);
    Mat24 A, Bp;
    A << Q.col(0).transpose(), Q.col(1).transpose();
    Bp << Q.col(2).transpose(), Q.col(3).transpose();
    const double d = std::min(plane_distance(plane_of(s.first), A), plane_distance(plane_of(s.first), Bp));
    INFO("trial " << trial << ": off-block " << s.off_block << ", distance to the nearer true plane " << d);
    CHECK(d < 1e-5);
    CHECK(s.off_block < 1e-8);
  }
}

namespace {

// The distances of the structured search's seed planes (the split of the
// residual's Hessians at structure_radius) to the nearer true plane.
std::pair<double, double> seed_distances(const PlantedProductBrdf& b, int grid, Parameterization p,
                                         PlaneSplit* split = nullptr) {
  const SampleSet s = sample_grid(b, grid);
  const FitData d(s, 1e-5);
  std::vector<double> y(d.size());
  for (size_t k = 0; k < y.size(); ++k) y[k] = (d.g[0][k] + d.g[1][k] + d.g[2][k]) / 3;
  StructureOptions so;
  so.radius = structure_radius(d.size());
  const PlaneSplit sp = split_planes(local_hessians(d.points(p), y, d.w, so));
  if (split) *split = sp;
  const Mat24 &A = b.terms()[0].P, &B = b.terms()[1].P;
  return {std::min(plane_distance(plane_of(sp.first), A), plane_distance(plane_of(sp.first), B)),
          std::min(plane_distance(plane_of(sp.second), A), plane_distance(plane_of(sp.second), B))};
}

}  // namespace

TEST_CASE("structure: the seed planes of a planted two-plane BRDF are near the true ones") {
  // Grid 10, both parameterizations, members 0..7: the Hessians are estimated,
  // not exact, so the planes are only close (measured distances 0.002..0.03;
  // bound 0.1). At the fixed radius 0.35 members 2 and 3 (wiwo) got mixed
  // planes (distance ~1); structure_radius(6,400 samples) is 0.55.
  CHECK(structure_radius(43264) == Approx(0.35));
  CHECK(structure_radius(6400) == Approx(0.35 * std::pow(40000.0 / 6400, 0.25)));
  CHECK(structure_radius(10) == Approx(0.8));
  for (Parameterization p : {Parameterization::WiWo, Parameterization::HalfDiff}) {
    for (int i = 0; i < 8; ++i) {
      const PlantedProductBrdf b = planted_rotation_brdf(i, 2, p);
      PlaneSplit sp;
      const auto [d1, d2] = seed_distances(b, 10, p, &sp);
      INFO(b.to_string() << ": distances " << d1 << ", " << d2 << ", off-block " << sp.off_block);
      CHECK(d1 < 0.1);
      CHECK(d2 < 0.1);
    }
  }
}

TEST_CASE("structure: the seed planes of planted member 12 (halfdiff, 16^4 grid) are the true ones") {
  // The eigenvectors of sum H^2 mix its planes (off-block 0.077, distance 1
  // before split_planes tried random combinations; measured now 0.001 and 0.000).
  const PlantedProductBrdf b = planted_rotation_brdf(12, 2, Parameterization::HalfDiff);
  PlaneSplit sp;
  const auto [d1, d2] = seed_distances(b, 16, Parameterization::HalfDiff, &sp);
  INFO(b.to_string() << ": distances " << d1 << ", " << d2 << ", off-block " << sp.off_block);
  CHECK(d1 < 0.05);
  CHECK(d2 < 0.05);
  CHECK(sp.off_block < 0.01);
}

namespace {

// Planted member 0 (wiwo, two planes), grid 10, texture 8 (small, so the
// default suite stays fast), searched by the structured and the greedy search.
struct TwoPlaneCase {
  const PlantedProductBrdf b = planted_rotation_brdf(0, 2, Parameterization::WiWo);
  const SampleSet s = sample_grid(b, 10);
  const FitData d{s, 1e-5};
  const SearchResult r = search_factorization(d, structured(2, 8));
  const SearchResult rg = search_factorization(d, greedy());
  static SearchOptions greedy() {
    SearchOptions g = structured(2, 8);
    g.strategy = "greedy";
    return g;
  }
};

}  // namespace

TEST_CASE("structured search: a planted two-plane BRDF ends near the floor, the greedy search does not") {
  // Bound: 1.5x the floor (measured 0.4x..0.9x on members 0..2: the search
  // may also turn the texture axes inside the true planes, which the floor
  // does not).
  const TwoPlaneCase c;
  const double fl = floor_error(c.b, c.d, 8);
  INFO("floor " << fl << ", structured " << c.r.rel_mse_after_term.back() << " (" << c.r.evaluations
                << " fits), greedy " << c.rg.rel_mse_after_term.back() << " (" << c.rg.evaluations << " fits)");
  CHECK(c.r.rel_mse_after_term.back() <= 1.5 * fl);
  CHECK(c.rg.rel_mse_after_term.back() > 1.5 * fl);  // the trap this search exists for
  CHECK(c.r.strategy == "structured");
  CHECK(c.rg.strategy == "greedy");
}

TEST_CASE("structured search: best keeps the structured answer whole on a planted two-plane BRDF", "[heavy]") {
  const TwoPlaneCase c;
  // strategy = "best" runs both and keeps the structured answer here, whole.
  SearchOptions both = structured(2, 8);
  both.strategy = "best";
  const SearchResult rb = search_factorization(c.d, both);
  CHECK(rb.strategy == "structured");
  CHECK(rb.rel_mse_after_term == c.r.rel_mse_after_term);
  CHECK(rb.evaluations == c.r.evaluations + c.rg.evaluations);
  CHECK(rb.factorization->eval(Vec3(0.3, 0.1, 0.95).normalized(), Vec3(-0.2, 0.4, 0.89).normalized())
            .isApprox(c.r.factorization->eval(Vec3(0.3, 0.1, 0.95).normalized(), Vec3(-0.2, 0.4, 0.89).normalized())));
  // With a stopping rule (a tolerance) it is the greedy search alone.
  SearchOptions g = TwoPlaneCase::greedy();
  both.stop_after_term = [](const HomomorphicFactorization&) { return false; };
  g.stop_after_term = both.stop_after_term;
  const SearchResult rt = search_factorization(c.d, both);
  CHECK(rt.strategy == "greedy");
  CHECK(rt.rel_mse_after_term == search_factorization(c.d, g).rel_mse_after_term);
}

TEST_CASE("structured search: deterministic for a seed, whatever the thread count") {
  const PlantedProductBrdf b = planted_rotation_brdf(1, 2, Parameterization::HalfDiff);
  const SampleSet s = sample_grid(b, 8);
  const FitData d(s, 1e-5);
  SearchOptions opt = structured(2, 6);
  opt.threads = 1;
  const SearchResult a = search_factorization(d, opt);
  opt.threads = 2;
  const SearchResult c = search_factorization(d, opt);
  CHECK(a.rel_mse_after_term == c.rel_mse_after_term);
  CHECK(a.evaluations == c.evaluations);
  REQUIRE(a.terms.size() == 2);
  CHECK(a.terms[1].rotation == c.terms[1].rotation);
}

TEST_CASE("structured search: planted family, both parameterizations, 2 and 3 terms", "[slow]") {
  // Grid 10, texture 8. Bounds: 2x the floor (2 terms) and 3x (3 terms), the
  // issue's targets at texture 16 (measured here: docs/search.md). Members 2
  // and 3 (wiwo) ended at 2.4x and 4.7x the floor when the seeds' Hessians
  // used the radius of a 16^4 grid on this sparser one (structure_radius).
  for (int terms : {2, 3})
    for (Parameterization p : {Parameterization::WiWo, Parameterization::HalfDiff})
      for (int i = 0; i < (terms == 2 ? 4 : 2); ++i) {
        const PlantedProductBrdf b = planted_rotation_brdf(i, terms, p);
        const SampleSet s = sample_grid(b, 10);
        const FitData d(s, 1e-5);
        const double fl = floor_error(b, d, 8);
        const SearchResult r = search_factorization(d, structured(terms, 8));
        INFO(b.to_string() << ": floor " << fl << ", structured " << r.rel_mse_after_term.back());
        CHECK(r.rel_mse_after_term.back() <= (terms == 2 ? 2.0 : 3.0) * fl);
      }
}

TEST_CASE("planted: the 4-term member has two planes in each parameterization") {
  const PlantedProductBrdf b = planted_rotation_brdf(0, 4, Parameterization::WiWo);
  REQUIRE(b.terms().size() == 4);
  CHECK(b.terms()[0].param == Parameterization::WiWo);
  CHECK(b.terms()[1].param == Parameterization::WiWo);
  CHECK(b.terms()[2].param == Parameterization::HalfDiff);
  CHECK(b.terms()[3].param == Parameterization::HalfDiff);
  // Each parameterization's two planes are orthogonal (planes of one rotation).
  CHECK(plane_distance(b.terms()[0].P, b.terms()[1].P) == Approx(2).margin(1e-12));
  CHECK(plane_distance(b.terms()[2].P, b.terms()[3].P) == Approx(2).margin(1e-12));
  // The 2- and 3-term members are what they were (the 4-term one draws after them).
  const PlantedProductBrdf b3 = planted_rotation_brdf(0, 3, Parameterization::WiWo);
  CHECK(b3.terms().size() == 3);
  CHECK_THROWS_AS(planted_rotation_brdf(0, 5, Parameterization::WiWo), std::invalid_argument);
}

TEST_CASE("planted: nearest_plane_distance is 0 at a true plane and counts only its parameterization") {
  const PlantedProductBrdf b = planted_rotation_brdf(0, 3, Parameterization::WiWo);  // w, w, h
  for (const PlantedTerm& t : b.terms()) CHECK(b.nearest_plane_distance(t.param, t.P) == Approx(0).margin(1e-12));
  // The halfdiff plane read as wiwo is compared with the two wiwo planes only.
  const Mat24& h = b.terms()[2].P;
  CHECK(b.nearest_plane_distance(Parameterization::WiWo, h) ==
        Approx(std::min(plane_distance(h, b.terms()[0].P), plane_distance(h, b.terms()[1].P))));
  CHECK(b.nearest_plane_distance(Parameterization::WiWo, h) > 1e-3);
  // No term of a parameterization: the largest distance.
  const PlantedProductBrdf two = planted_rotation_brdf(0, 2, Parameterization::WiWo);
  CHECK(two.nearest_plane_distance(Parameterization::HalfDiff, two.terms()[0].P) == 2);
}

TEST_CASE("structured search: mixed planted family ends near the joint floor", "[slow]") {
  // Two planes in one parameterization and one (3 terms) or two (4 terms) in
  // the other; 16^4 grid, texture 16. The floor is the fit at all true planes
  // solved jointly; bounds 2x (3 terms) and 3x (4 terms). Before the joint
  // re-seeding (Structured::reseed) these members ended 5.5x-30x above it,
  // but for member 0 (3 terms, wiwo); before its pair moves, member 1 in
  // halfdiff ended at 11.9x (3 terms: its halfdiff pair stayed mixed) and
  // 11.8x (4 terms: every term wiwo).
  for (int i : {0, 1})
    for (int terms : {3, 4})
      for (Parameterization p : {Parameterization::WiWo, Parameterization::HalfDiff}) {
        const PlantedProductBrdf b = planted_rotation_brdf(i, terms, p);
        const SampleSet s = sample_grid(b, 16);
        const FitData d(s, 1e-5);
        const double fl = joint_floor_error(b, d, 16);
        const SearchResult r = search_factorization(d, structured(terms, 16));
        INFO(b.to_string() << ": joint floor " << fl << ", structured " << r.rel_mse_after_term.back() << " ("
                           << r.evaluations << " fits)");
        CHECK(r.rel_mse_after_term.back() <= (terms == 3 ? 2.0 : 3.0) * fl);
      }
}

TEST_CASE("structured search: a new mix of parameterizations gets its own pair restarts", "[slow]") {
  // Mixed member 3, 4 terms, wiwo main parameterization, seed 1. Re-seeding's
  // first round turns the mix w w w h into h w w h on wrong planes; with pair
  // restarts only in that first round the search ended there, 11.5x the joint
  // floor with no plane within 0.3 of a true one (seeds 2 and 3: 1.07x and
  // 0.58x). Restarting the new mix's pairs finds all four planes (0.59x).
  // Every found plane is a true plane of its parameterization.
  check_mixed_member(3, 4, Parameterization::WiWo, 3.0, 0.01);
}

TEST_CASE("structured search: the polish starts from the lower of the beam and the side configuration", "[slow]") {
  // Mixed member 5, 3 terms, wiwo main parameterization, seed 1. The last
  // stage's side configuration (the greedy extension) is lower than every
  // beam configuration; polishing and re-seeding the beam's best ended at
  // 0.0044 and the unpolished side configuration (one wiwo plane 0.0136 off)
  // became the answer, 8.1x the joint floor. Polished from the side
  // configuration the search finds all three planes (0.66x).
  check_mixed_member(5, 3, Parameterization::WiWo, 2.0, 0.005);
}

TEST_CASE("structured search: re-seeding keeps a replacement that changes the mix", "[slow]") {
  // Mixed member 8, 3 terms, wiwo main parameterization, seed 1. The search
  // ends its polish at w w w (19.4x the joint floor). Re-seeding's
  // replacement of term 0 read as halfdiff is within 2x of that and
  // polishes to the true planes, but each subset kept only its lower
  // replacement over both parameterizations (the wiwo one), so no mix but
  // w w w was ever polished. One replacement per parameterization (the
  // higher one read for a mix no other candidate has): 0.73x.
  CHECK(wiwo_terms(check_mixed_member(8, 3, Parameterization::WiWo, 2.0, 0.005)) == 2);
}

TEST_CASE("structured search: re-seeding moves a term alone to the other parameterization", "[slow]") {
  // Mixed member 7, 3 terms, halfdiff main parameterization (two halfdiff
  // terms, one wiwo), seed 1. Re-seeding ended at h h h, one halfdiff term
  // 0.76 from any true plane, 12.6x the joint floor: that term read as wiwo
  // seeds at 0.027-0.030, 5x the objective then, so no round polished it.
  // Powell on that term alone in wiwo from the seed reaches the true wiwo
  // plane (reseed_switch): 0.62x, every plane within 0.001.
  CHECK(wiwo_terms(check_mixed_member(7, 3, Parameterization::HalfDiff, 2.0, 0.005)) == 1);
}

TEST_CASE("structured search: re-seeding also runs from the beam's next configuration", "[slow]") {
  // Mixed member 6, 3 terms, wiwo main parameterization (w w h), search seed
  // 2. Re-seeding from the polished best configuration ended at w w w with
  // every plane 0.98-1.0 from a true one, 36.5x the joint floor, and no
  // single-term Powell run in either parameterization left it. Re-seeding
  // again from the beam's next configuration finds all three planes (0.65x;
  // 38,232 fits against 17,844).
  CHECK(wiwo_terms(check_mixed_member(6, 3, Parameterization::WiWo, 2.0, 0.005, 2)) == 2);
}

TEST_CASE("structured search: the one-term move also reads the residual of the others refit without the term",
          "[slow]") {
  // Two answers with one term on a wrong plane, each 12x the joint floor,
  // that Powell on that term alone leaves only from a seed of the residual
  // with the others refit without it (the joint fit's residual, where the
  // others have adapted to the wrong term, leads back to 12x-38x).
  // Mixed member 5, 3 terms, wiwo, search seed 2: w w h with the halfdiff
  // term 0.85 off; from the refit residual, in halfdiff, it reaches its
  // true plane (0.67x, 86,292 fits).
  CHECK(wiwo_terms(check_mixed_member(5, 3, Parameterization::WiWo, 2.0, 0.005, 2)) == 2);
  // Mixed member 7, 3 terms, halfdiff, search seed 3: h h h with one
  // halfdiff term 0.78 off; the second plane of the refit residual's wiwo
  // split reaches the true wiwo plane (0.61x, 77,185 fits).
  CHECK(wiwo_terms(check_mixed_member(7, 3, Parameterization::HalfDiff, 2.0, 0.005, 3)) == 1);
}

TEST_CASE("structured search: a 2-term pair across parameterizations finds both planes") {
  // A wiwo plane and a halfdiff plane (planted_mixed_pair_brdf, halfdiff
  // first), grid 10, texture 8. Without re-seeding at 2 terms the search
  // ended with both terms in wiwo, one of them on no true plane: member 0 at
  // 1.73x the joint floor (the wrong plane 1.6 off), member 3 at 2.48x (1.2
  // off). Re-seeding's one-term move (reseed_switch) takes that term to
  // halfdiff: 0.82x and 0.88x, every plane within 0.003.
  // Member 1 ended with both terms in wiwo on two wrong planes (2.21x, 0.99
  // and 0.83 off), which no one-term move leaves; the mixed pair's random
  // restarts (reseed_mixed_pair) reach both true planes: 0.60x, within 0.001.
  // Members 1 and 3 at texture 8: the [heavy] test below.
  check_pair(0, Parameterization::HalfDiff, 10, 8, 1.2, 0.01);
  // At texture 12 those restarts search at texture 8 (half the search's,
  // kPairRestartMinTexture) and the pair they keep is read and polished at
  // 12: member 1 ends at 0.90x (14.7x, both terms in wiwo, without them).
  check_pair(1, Parameterization::HalfDiff, 10, 12, 1.2, 0.01);
}

TEST_CASE("structured search: more 2-term pairs across parameterizations find both planes", "[heavy]") {
  // Members 1 and 3 of the test above at texture 8 (the one-term move and
  // the mixed pair's restarts, which that test runs too).
  for (int member : {1, 3}) check_pair(member, Parameterization::HalfDiff, 10, 8, 1.2, 0.01);
}

TEST_CASE("structured search: a 2-term answer in one parameterization is restarted in that mix too") {
  // Cole's Cook-Torrance, 16^4 grid, texture 8, seed 1. With the mixed
  // pair's restarts in wiwo + halfdiff only, the search ended at w h,
  // 0.2086; 8 random halfdiff + halfdiff pairs (the mix of the answer
  // before the restarts) find h h at 0.1003. The same trap on the
  // model's MERL table: 0.0802 against 0.0582 (docs/search.md, "Search on
  // a subsample").
  const BrdfPtr b = Catalogue::builtin().make("cole-cook-torrance");
  const SampleSet s = sample_grid(*b, 16);
  const FitData d(s, 1e-5);
  const SearchResult r = search_factorization(d, structured(2, 8));
  INFO("rel_mse " << r.rel_mse_after_term.back() << " (" << r.evaluations << " fits)");
  CHECK(r.rel_mse_after_term.back() < 0.12);
  CHECK(wiwo_terms(r) == 0);
}

TEST_CASE("structured search: 2-term pairs across parameterizations end near the joint floor", "[slow]") {
  // planted_mixed_pair_brdf, 16^4 grid, texture 16, seed 1: members 0-7 at
  // 0.30x-0.99x the joint floor with every plane within 7e-5 (docs/search.md,
  // "Pairs across parameterizations"). Member 1 with halfdiff first ended at
  // 55x with both terms in wiwo before the mixed pair's restarts.
  for (int member : {0, 1, 2, 3, 4, 5})
    for (Parameterization first : {Parameterization::WiWo, Parameterization::HalfDiff})
      check_pair(member, first, 16, 16, 2.0, 0.005);
}

TEST_CASE("structured search: McCool's form is inside the search space and survives export") {
  // f = p(wi) q(h) p(wo): three terms, wiwo, wiwo and halfdiff. Grid 10,
  // texture 8; measured 0.89x and 1.05x McCool's error on members 0 and 1
  // (bound 3x, the target).
  const PlantedProductBrdf b = planted_mccool_brdf(0);
  const SampleSet s = sample_grid(b, 10);
  const FitData d(s, 1e-5);
  std::vector<double> em;
  fit_homomorphic(d, mccool_terms(8), FitOptions{}, "mccool", &em);
  // The re-seeding step (tested on the mixed family) is off: it doubles this test's time.
  SearchOptions so = structured(3, 8);
  so.reseed = false;
  const SearchResult r = search_factorization(d, so);
  INFO("McCool " << em.back() << ", structured " << r.rel_mse_after_term.back() << " (" << r.evaluations
                 << " fits)");
  CHECK(r.rel_mse_after_term.back() <= 3 * em.back());
  int halfdiff = 0;
  for (const FactorTerm& t : r.factorization->terms()) halfdiff += t.proj.param == Parameterization::HalfDiff;
  CHECK(halfdiff == 1);  // q(h); p(wi) and p(wo) read the wiwo point

  // Export and reload: the mixed parameterizations evaluate identically.
  bf_test::TempDir dir("structured_export");
  const ExportedFiles files = write_factorization(*r.factorization, dir.path.string(), "factors");
  const auto g = load_factorization(files.sidecar);
  REQUIRE(g->terms().size() == 3);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> U(0, 1);
  for (int k = 0; k < 200; ++k) {
    const Vec3 wi = from_spherical(std::acos(std::max(U(rng), 0.05)), 2 * M_PI * U(rng));
    const Vec3 wo = from_spherical(std::acos(std::max(U(rng), 0.05)), 2 * M_PI * U(rng));
    const Rgb a = r.factorization->eval(wi, wo), c = g->eval(wi, wo);
    CHECK((a - c).cwiseAbs().maxCoeff() <= 1e-6 * std::max(1.0, a.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("structured search: McCool's form, members 0-5, ends within 1.2x McCool's error", "[slow]") {
  // Grid 10, texture 8; measured 0.89x-1.01x. Member 5 ended at 1.32x (and
  // 9.0x on the 16^4 grid) before the fine polish of small searches: the
  // planes were found but Powell's coarse line search stopped short of them.
  for (int i = 0; i < 6; ++i) {
    const PlantedProductBrdf b = planted_mccool_brdf(i);
    const SampleSet s = sample_grid(b, 10);
    const FitData d(s, 1e-5);
    std::vector<double> em;
    fit_homomorphic(d, mccool_terms(8), FitOptions{}, "mccool", &em);
    const SearchResult r = search_factorization(d, structured(3, 8));
    INFO(b.to_string() << ": McCool " << em.back() << ", structured " << r.rel_mse_after_term.back());
    CHECK(r.rel_mse_after_term.back() <= 1.2 * em.back());
  }
}

namespace {

// For every term count k, the structured search's k-term answer against the
// greedy search's k-term answer in both parameterizations (the better of the
// two), and the answers' own consistency.
void check_k_term_answers(const SampleSet& s, int terms, int texture, bool reciprocity) {
  const FitData d(s, 1e-5);
  SearchOptions opt = structured(terms, texture);
  opt.reciprocity = reciprocity;
  const SearchResult r = search_factorization(d, opt);
  REQUIRE(r.answers.size() == static_cast<size_t>(terms));
  REQUIRE(r.rel_mse_after_term.size() == static_cast<size_t>(terms));
  CHECK(r.answers.back() == r.factorization);
  std::vector<double> best_greedy(terms, 1e300), same_param(terms);
  for (Parameterization p : {Parameterization::WiWo, Parameterization::HalfDiff}) {
    SearchOptions g = opt;
    g.strategy = "greedy";
    g.param = p;
    const SearchResult rg = search_factorization(d, g);
    for (int k = 0; k < terms; ++k) best_greedy[k] = std::min(best_greedy[k], rg.rel_mse_after_term[k]);
    if (p == opt.param) same_param = rg.rel_mse_after_term;
  }
  // The first term runs Powell from every start of the greedy search with the
  // same seed, restarts and parameterization: its answer is never worse, to
  // rounding.
  INFO("1 term: structured " << r.rel_mse_after_term[0] << ", greedy (same parameterization) " << same_param[0]);
  CHECK(r.rel_mse_after_term[0] <= same_param[0] * (1 + 1e-9));
  for (int k = 0; k < terms; ++k) {
    INFO((k + 1) << " terms: structured " << r.rel_mse_after_term[k] << ", best greedy " << best_greedy[k]);
    // The k-term answer is a k-term factorization whose error is the one reported
    // (the metrics score its float texels, the fit its double sums).
    REQUIRE(r.answers[k]);
    CHECK(r.answers[k]->terms().size() == static_cast<size_t>(k + 1));
    CHECK(evaluate_metrics(*r.answers[k], s, d.transform).rel_mse ==
          Approx(r.rel_mse_after_term[k]).epsilon(1e-5));
    // Powell stops when a sweep gains less than ftol (1e-3, relative): two runs
    // ending in the same minimum differ by about that much.
    CHECK(r.rel_mse_after_term[k] <= best_greedy[k] * (1 + 2 * PowellOptions{}.ftol));
    // ... and no worse than the final answer's k-term prefix, refit jointly.
    std::vector<TermSpec> prefix;
    for (int i = 0; i <= k; ++i) {
      const FactorTerm& t = r.factorization->terms()[i];
      prefix.push_back(TermSpec{t.proj, t.reciprocal, t.rotation});
    }
    FitOptions fo;
    fo.solve_last = k + 1;
    std::vector<double> e;
    fit_homomorphic(d, prefix, fo, "prefix", &e);
    CHECK(r.rel_mse_after_term[k] <= e.back() * (1 + 1e-9));
  }
}

}  // namespace

TEST_CASE("structured search: every k-term answer is no worse than the greedy k-term answer") {
  // A planted two-plane BRDF (grid 10, texture 8, 2 terms): the 1-term answer
  // must match the greedy search's best single plane (the beam's 2-term answer
  // does not contain it). Not a guarantee in general: docs/search.md lists the
  // measured BRDFs and term counts where the greedy search is better.
  const PlantedProductBrdf b = planted_rotation_brdf(0, 2, Parameterization::WiWo);
  check_k_term_answers(sample_grid(b, 10), 2, 8, false);
}

TEST_CASE("structured search: the 1-term answer is never worse than the greedy search at the same seed") {
  // With one parameterization the old start selection (Powell from the `keep`
  // best screened starts) missed the greedy search's best single plane on W1
  // at every seed: 0.0913 against 0.0788 at seed 1 (grid 10, texture 8). The
  // first term now runs Powell from every greedy start as well.
  for (const char* spec : {"bluepaint", "cook-torrance"}) {
    const BrdfPtr b = Catalogue::builtin().make(spec);
    const FitData d(sample_grid(*b, 10), 1e-5);
    for (uint64_t seed : {1, 2, 4}) {
      SearchOptions opt = structured(1, 8);
      opt.term_param = "fixed";
      opt.seed = seed;
      const SearchResult r = search_factorization(d, opt);
      SearchOptions g = opt;
      g.strategy = "greedy";
      const SearchResult rg = search_factorization(d, g);
      INFO(spec << " seed " << seed << ": structured " << r.rel_mse_after_term[0] << ", greedy "
                << rg.rel_mse_after_term[0]);
      CHECK(r.rel_mse_after_term[0] <= rg.rel_mse_after_term[0] * (1 + 1e-9));
    }
  }
}

TEST_CASE("structured search: the beam and the polish follow the search size unless set") {
  // Searches of up to kSmallSearchTerms (4) terms keep a beam of 8 and polish
  // with 2 sweeps (the planted two-plane search needs the beam); longer ones a
  // beam of 4 and no polish. A value the caller sets is used at every size.
  SearchOptions o = structured(kSmallSearchTerms, 8);
  CHECK(effective_beam_width(o) == 8);
  CHECK(effective_polish_sweeps(o) == 2);
  o.terms = kSmallSearchTerms + 1;
  CHECK(effective_beam_width(o) == 4);
  CHECK(effective_polish_sweeps(o) == 0);
  o.beam_width = 8;
  o.polish_sweeps = 1;
  CHECK(effective_beam_width(o) == 8);
  CHECK(effective_polish_sweeps(o) == 1);
  o.terms = 2;
  o.polish_sweeps = 0;
  CHECK(effective_polish_sweeps(o) == 0);
  // What the search runs: a 5-term search by default is the one with beam 4
  // and no polish, bit for bit; an explicit polish_sweeps polishes it (its
  // re-search fits are booked on the last term's record).
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const FitData d(sample_grid(*b, 8), 1e-5);
  const SearchOptions def = structured(5, 6);
  SearchOptions narrow = def;
  narrow.beam_width = 4;
  narrow.polish_sweeps = 0;
  SearchOptions polished = def;
  polished.polish_sweeps = 2;
  const SearchResult r = search_factorization(d, def);
  const SearchResult rn = search_factorization(d, narrow);
  const SearchResult rp = search_factorization(d, polished);
  CHECK(r.rel_mse_after_term == rn.rel_mse_after_term);
  CHECK(r.evaluations == rn.evaluations);
  CHECK(r.terms.back().backfit_evaluations == 0);
  CHECK(rp.terms.back().backfit_evaluations > 0);
  CHECK(rp.evaluations > r.evaluations);
}

TEST_CASE("structured search: term_param fixed puts every term and every k-term answer on the given parameterization") {
  // McCool's form mixes wiwo and halfdiff: with term_param = "either" the
  // structured search reads both points (the control), with "fixed" none of
  // its starts, refinements, polish moves or k-term answers may read the other.
  const PlantedProductBrdf b = planted_mccool_brdf(0);
  const SampleSet s = sample_grid(b, 6);
  const FitData d(s, 1e-5);
  const auto params_of = [](const HomomorphicFactorization& f) {
    std::set<Parameterization> out;
    for (const FactorTerm& t : f.terms()) out.insert(t.proj.param);
    return out;
  };
  SearchOptions either = structured(2, 6);
  either.restarts = 2;
  const SearchResult mixed = search_factorization(d, either);
  CHECK(params_of(*mixed.factorization).size() == 2);  // the control: "either" does choose per term
  // "best" with halfdiff: its greedy half reads `param` too, not wiwo.
  for (const auto& [p, strategy] : std::vector<std::pair<Parameterization, std::string>>{
           {Parameterization::WiWo, "structured"},
           {Parameterization::HalfDiff, "structured"},
           {Parameterization::HalfDiff, "best"}}) {
    SearchOptions opt = structured(2, 6);
    opt.strategy = strategy;
    opt.restarts = 2;
    opt.term_param = "fixed";
    opt.param = p;
    const SearchResult r = search_factorization(d, opt);
    INFO(strategy << " " << to_string(p) << ", won by " << r.strategy);
    CHECK(params_of(*r.factorization) == std::set<Parameterization>{p});
    CHECK(r.factorization->terms().size() == 2);
    for (const auto& a : r.answers) {
      REQUIRE(a);
      CHECK(params_of(*a) == std::set<Parameterization>{p});
    }
  }
}

TEST_CASE("structured search: final_reciprocity refits each answer with reciprocal terms and keeps the lower") {
  // Reciprocal data (W1's Lafortune paint on a grid, closed under the swap):
  // the swap-average of an answer is a fit with the same planes and
  // reciprocal terms, so the reciprocal refit is never higher, and here it is
  // lower at every term count. The planes stay those of the search.
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  REQUIRE(b->reciprocal());
  const SampleSet s = sample_grid(*b, 8);
  const FitData d(s, 1e-5);
  SearchOptions opt = structured(2, 6);
  opt.restarts = 2;
  opt.threads = 2;
  const SearchResult r0 = search_factorization(d, opt);
  CHECK(r0.reciprocal_answers.empty());
  opt.final_reciprocity = true;
  const SearchResult r1 = search_factorization(d, opt);
  REQUIRE(r1.reciprocal_answers.size() == 2);
  for (size_t k = 0; k < 2; ++k) {
    INFO((k + 1) << " terms: without " << r0.rel_mse_after_term[k] << ", with " << r1.rel_mse_after_term[k]);
    CHECK(r1.reciprocal_answers[k]);
    CHECK(r1.rel_mse_after_term[k] < r0.rel_mse_after_term[k]);
    REQUIRE(r1.answers[k]->terms().size() == k + 1);
    for (size_t i = 0; i <= k; ++i) {
      const FactorTerm& t1 = r1.answers[k]->terms()[i];
      const FactorTerm& t0 = r0.answers[k]->terms()[i];
      CHECK(t1.reciprocal);
      CHECK_FALSE(t0.reciprocal);
      CHECK(t1.proj.param == t0.proj.param);
      CHECK(t1.rotation == t0.rotation);
    }
    // The reported error is the answer's.
    CHECK(evaluate_metrics(*r1.answers[k], s, d.transform).rel_mse == Approx(r1.rel_mse_after_term[k]).epsilon(1e-5));
  }
  CHECK(r1.factorization == r1.answers.back());
  // Not a rounding-level gain: on this grid the 2-term answer falls by more than 10% (0.0279 -> 0.0224).
  CHECK(r1.rel_mse_after_term[1] < 0.9 * r0.rel_mse_after_term[1]);
}

namespace {

// Bluepaint, grid 8, a 3-term structured search (texture 6, 2 restarts) with
// the reciprocal answers, and a stopping rule that records what it is shown
// and never stops the search.
struct StopRuleCase {
  const BrdfPtr b = Catalogue::builtin().make("bluepaint");
  const SampleSet s = sample_grid(*b, 8);
  const FitData d{s, 1e-5};
  const LogTransform lt = LogTransform::of(s, 1e-5);
  const SearchOptions opt = options();
  std::vector<std::pair<size_t, double>> seen;  // (terms, rel_mse) of what the rule is shown
  SearchResult all;

  StopRuleCase() {
    SearchOptions o = opt;
    o.stop_after_term = [this](const HomomorphicFactorization& h) {
      seen.emplace_back(h.terms().size(), evaluate_metrics(h, s, lt).rel_mse);
      return false;
    };
    all = search_factorization(d, o);
  }
  static SearchOptions options() {
    SearchOptions o = structured(3, 6);
    o.restarts = 2;
    o.threads = 2;
    o.final_reciprocity = true;
    return o;
  }
  // A tolerance between the 2-term answer and its reciprocal refit (lower here).
  double target() const { return 0.5 * (seen.at(2).second + seen.at(3).second); }
  // The options with a stopping rule that accepts an answer at or below `tol`.
  SearchOptions stopping_at(double tol) const {
    SearchOptions o = opt;
    o.stop_after_term = [this, tol](const HomomorphicFactorization& h) {
      return evaluate_metrics(h, s, lt).rel_mse <= tol;
    };
    return o;
  }
};

}  // namespace

TEST_CASE("structured search: a stopping rule judges the answer final_reciprocity keeps") {
  // A tolerance that the k-term answer's reciprocal refit meets, and the
  // answer before it does not, ends the search at k terms with that refit as
  // its answer (not one term later, as when the rule saw only the search's fit).
  StopRuleCase c;
  REQUIRE(c.all.rel_mse_after_term.size() == 3);
  // After terms 1 and 2: the search's answer, then its reciprocal refit (lower here).
  REQUIRE(c.seen.size() == 4);
  CHECK(c.seen[2].first == 2);
  CHECK(c.seen[3].first == 2);
  INFO("2 terms: answer " << c.seen[2].second << ", reciprocal refit " << c.seen[3].second);
  REQUIRE(c.seen[3].second < c.seen[2].second);
  REQUIRE(c.seen[1].second > c.seen[2].second);
  const double target = c.target();
  const SearchResult two = search_factorization(c.d, c.stopping_at(target));
  REQUIRE(two.rel_mse_after_term.size() == 2);
  CHECK(two.reciprocal_answers.at(1));
  CHECK(evaluate_metrics(*two.factorization, c.s, c.lt).rel_mse <= target);
  CHECK(two.evaluations < c.all.evaluations);
}

TEST_CASE("structured search: a stopping rule changes nothing in the search and its own fits count", "[heavy]") {
  StopRuleCase c;
  REQUIRE(c.seen.size() == 4);
  // The rule changes nothing in the search, and its own fits count: after
  // terms 1 and 2 the answer again and its reciprocal refit (2 fits each).
  const SearchResult none = search_factorization(c.d, c.opt);
  CHECK(none.rel_mse_after_term == c.all.rel_mse_after_term);
  CHECK(c.all.evaluations == none.evaluations + 4);
  // Without the reciprocal answers the tolerance the 2-term reciprocal
  // refit meets takes a third term.
  SearchOptions opt = c.stopping_at(c.target());
  opt.final_reciprocity = false;
  CHECK(search_factorization(c.d, opt).rel_mse_after_term.size() == 3);
}

TEST_CASE("structured search: final_reciprocity keeps an answer whose reciprocal refit is higher") {
  // A planted two-plane BRDF is not reciprocal: its 2-term answer (the true
  // planes, at the floor) fits worse read through the conjugates too and
  // stays as it was. Every answer is the lower of the two fits.
  const PlantedProductBrdf b = planted_rotation_brdf(0, 2, Parameterization::WiWo);
  REQUIRE_FALSE(b.reciprocal());
  const FitData d(sample_grid(b, 8), 1e-5);
  SearchOptions opt = structured(2, 8);
  opt.restarts = 2;
  opt.threads = 2;
  const SearchResult r0 = search_factorization(d, opt);
  opt.final_reciprocity = true;
  const SearchResult r1 = search_factorization(d, opt);
  REQUIRE(r1.reciprocal_answers.size() == 2);
  for (size_t k = 0; k < 2; ++k) {
    std::vector<TermSpec> sp;
    for (const FactorTerm& t : r0.answers[k]->terms()) sp.push_back(TermSpec{t.proj, true, t.rotation});
    FitOptions fo;
    fo.solve_last = static_cast<int>(k + 1);
    std::vector<double> e;
    fit_homomorphic(d, sp, fo, "reciprocal", &e);
    INFO((k + 1) << " terms: without " << r0.rel_mse_after_term[k] << ", reciprocal refit " << e.back()
                 << ", answer " << r1.rel_mse_after_term[k]);
    CHECK(r1.reciprocal_answers[k] == (e.back() < r0.rel_mse_after_term[k]));
    CHECK(r1.rel_mse_after_term[k] == Approx(std::min(e.back(), r0.rel_mse_after_term[k])).epsilon(1e-12));
    for (const FactorTerm& t : r1.answers[k]->terms()) CHECK(t.reciprocal == r1.reciprocal_answers[k]);
  }
  CHECK_FALSE(r1.reciprocal_answers[1]);
  CHECK(r1.rel_mse_after_term[1] == r0.rel_mse_after_term[1]);
  // With reciprocity asked of the whole search there is nothing to refit.
  opt.reciprocity = true;
  opt.terms = 1;
  CHECK(search_factorization(d, opt).reciprocal_answers.empty());
}
