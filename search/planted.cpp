// Planted product BRDFs (see planted.h).
#include "search/planted.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "brdfs/sampleset.h"

namespace bf {

double PlaneFunction::operator()(const Eigen::Vector2d& u) const {
  double v = linear.dot(u) + 0.5 * u.dot(quadratic * u);
  for (const auto& b : bumps) {
    const double dx = u.x() - b[1], dy = u.y() - b[2];
    v += b[0] * std::exp(-(dx * dx + dy * dy) / (2 * b[3] * b[3]));
  }
  return scale * v;
}

PlaneFunction PlaneFunction::random(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  PlaneFunction f;
  f.linear = Eigen::Vector2d(U(rng), U(rng)) * 0.5;
  const double q = 0.4 * U(rng), r = 0.4 * U(rng), s = 0.4 * U(rng);
  f.quadratic << q, r, r, s;
  const int n = 2 + static_cast<int>((U(rng) + 1) * 1.5);  // 2..4 bumps
  for (int i = 0; i < n; ++i)
    f.bumps.push_back({1.0 + 0.5 * (U(rng) + 1), 0.7 * U(rng), 0.7 * U(rng), 0.3 + 0.1 * (U(rng) + 1)});
  return f;
}

PlantedProductBrdf::PlantedProductBrdf(std::vector<PlantedTerm> terms, std::string label)
    : terms_(std::move(terms)), label_(std::move(label)) {}

Rgb PlantedProductBrdf::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0 || wo.z() <= 0) return Rgb::Zero();
  double s = 0;
  for (const PlantedTerm& t : terms_) s += t.a(t.P * to_point(t.param, wi, wo));
  return Rgb(1.0, 0.8, 0.6) * std::exp(s);
}

double PlantedProductBrdf::nearest_plane_distance(Parameterization param, const Mat24& P) const {
  double dist = 2;
  for (const PlantedTerm& t : terms_)
    if (t.param == param) dist = std::min(dist, plane_distance(P, t.P));
  return dist;
}

std::vector<TermSpec> PlantedProductBrdf::specs(int res) const {
  std::vector<TermSpec> out;
  for (const PlantedTerm& t : terms_) {
    TermSpec s;
    s.proj.param = t.param;
    s.proj.P = t.P;
    s.proj.res = res;
    out.push_back(s);
  }
  return out;
}

namespace {
// Scales t.a so that its range over the pairs of the 12^2 direction grid is `range` (natural log).
void scale_to_range(PlantedTerm& t, double range) {
  static const std::vector<Vec3> dirs = grid_directions(12);
  double lo = 1e300, hi = -1e300;
  t.a.scale = 1;
  for (const Vec3& wi : dirs)
    for (const Vec3& wo : dirs) {
      const double v = t.a(t.P * to_point(t.param, wi, wo));
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  t.a.scale = hi > lo ? range / (hi - lo) : 1;
}

Mat24 plane(const Rotation4& R, int first_col) {
  const Eigen::Matrix4d M = R.matrix();
  Mat24 P;
  P.row(0) = M.col(first_col).transpose();
  P.row(1) = M.col(first_col + 1).transpose();
  return P;
}
}  // namespace

PlantedProductBrdf planted_rotation_brdf(int index, int terms, Parameterization param) {
  if (terms < 2 || terms > 4)
    throw std::invalid_argument("planted_rotation_brdf: terms: expected 2, 3 or 4, found " + std::to_string(terms));
  std::mt19937_64 rng(0x5eed0000ull + static_cast<uint64_t>(index) * 7919ull + terms * 104729ull +
                      (param == Parameterization::HalfDiff ? 1 : 0));
  std::uniform_real_distribution<double> U(0, 1);
  const Rotation4 R = Rotation4::random(rng);
  std::vector<PlantedTerm> ts(2);
  ts[0] = {param, plane(R, 0), PlaneFunction::random(rng)};
  ts[1] = {param, plane(R, 2), PlaneFunction::random(rng)};
  if (terms >= 3) {
    const Rotation4 R2 = Rotation4::random(rng);
    ts.push_back({other_parameterization(param), plane(R2, 0), PlaneFunction::random(rng)});
    if (terms == 4) ts.push_back({other_parameterization(param), plane(R2, 2), PlaneFunction::random(rng)});
  }
  const double share = 2.0 / terms;
  for (PlantedTerm& t : ts) scale_to_range(t, share * std::log(10.0) * (1.25 + 0.25 * U(rng)));
  return PlantedProductBrdf(std::move(ts), "planted-rotation(" + std::to_string(index) + ", " +
                                               std::to_string(terms) + " terms, " + to_string(param) + ")");
}

PlantedProductBrdf planted_mixed_pair_brdf(int index, Parameterization first) {
  std::mt19937_64 rng(0x9a1700ull + static_cast<uint64_t>(index) * 7919ull +
                      (first == Parameterization::HalfDiff ? 1 : 0));
  std::uniform_real_distribution<double> U(0, 1);
  const Rotation4 R = Rotation4::random(rng), R2 = Rotation4::random(rng);
  std::vector<PlantedTerm> ts = {{first, plane(R, 0), PlaneFunction::random(rng)},
                                 {other_parameterization(first), plane(R2, 0), PlaneFunction::random(rng)}};
  for (PlantedTerm& t : ts) scale_to_range(t, std::log(10.0) * (1.25 + 0.25 * U(rng)));
  return PlantedProductBrdf(std::move(ts), "planted-mixed-pair(" + std::to_string(index) + ", " + to_string(first) + " + " +
                                               to_string(other_parameterization(first)) + ")");
}

PlantedProductBrdf planted_mccool_brdf(int index) {
  std::mt19937_64 rng(0x3cc001ull + static_cast<uint64_t>(index) * 7919ull);
  const PlaneFunction p = PlaneFunction::random(rng), q = PlaneFunction::random(rng);
  const Rotation4 I = Rotation4::identity();
  std::vector<PlantedTerm> ts = {{Parameterization::WiWo, plane(I, 0), p},
                                 {Parameterization::WiWo, plane(I, 2), p},
                                 {Parameterization::HalfDiff, plane(I, 0), q}};
  scale_to_range(ts[0], std::log(10.0) * 0.9);
  ts[1].a.scale = ts[0].a.scale;  // the same p on wi and wo
  scale_to_range(ts[2], std::log(10.0) * 1.2);
  return PlantedProductBrdf(std::move(ts), "planted-mccool(" + std::to_string(index) + ")");
}

}  // namespace bf
