// Projections, masks and bilinear weights (see projection.h).
#include "factor/projection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace bf {

Projection Projection::conjugate() const {
  Projection c = *this;
  if (param == Parameterization::WiWo) {
    c.P.leftCols<2>() = P.rightCols<2>();
    c.P.rightCols<2>() = P.leftCols<2>();
  } else {
    c.P.rightCols<2>() = -P.rightCols<2>();
  }
  return c;
}

bool Projection::self_conjugate() const { return (conjugate().P - P).cwiseAbs().maxCoeff() < 1e-12; }

Eigen::Vector2d Projection::row_scale() const {
  return Eigen::Vector2d(1.0 / P.row(0).cwiseAbs().sum(), 1.0 / P.row(1).cwiseAbs().sum());
}

Eigen::Vector2d Projection::texel_coords(const Vec4& x) const {
  const Eigen::Vector2d u = (P * x).cwiseProduct(row_scale());
  return (u.array() + 1.0).matrix() * (0.5 * (res - 1));
}

void Projection::validate() const {
  if (res < 2 || res > 1024)
    throw std::invalid_argument("texture_size: expected 2..1024, found " + std::to_string(res));
  if (!P.allFinite()) throw std::invalid_argument("projection: matrix has non-finite entries");
  for (int r = 0; r < 2; ++r)
    if (std::abs(P.row(r).norm() - 1.0) > 1e-6)
      throw std::invalid_argument("projection: row " + std::to_string(r + 1) +
                                  " must have unit length, found length " +
                                  std::to_string(P.row(r).norm()));
  if (std::abs(P.row(0).dot(P.row(1))) > 1e-6)
    throw std::invalid_argument("projection: rows must be orthogonal, found dot product " +
                                std::to_string(P.row(0).dot(P.row(1))));
}

namespace {
double cross2(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// Convex hull (Andrew's monotone chain), counter-clockwise, no collinear points.
std::vector<Eigen::Vector2d> convex_hull(std::vector<Eigen::Vector2d> pts) {
  std::sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  std::vector<Eigen::Vector2d> h(2 * pts.size());
  size_t k = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(h[k - 2], h[k - 1], pts[i]) <= 0) --k;
    h[k++] = pts[i];
  }
  h.resize(k > 1 ? k - 1 : k);
  return h;
}

// Distance from p to the hull (0 inside). The inside test comes first (it
// needs no distances); outside, the smallest squared distance to an edge is
// taken and its square root (the same value as the smallest root).
double hull_distance(const std::vector<Eigen::Vector2d>& hull, const Eigen::Vector2d& p) {
  if (hull.size() == 1) return (p - hull[0]).norm();
  const size_t n = hull.size();
  if (n >= 3) {
    bool inside = true;
    for (size_t i = 0; i < n && inside; ++i) inside = cross2(hull[i], hull[i + 1 == n ? 0 : i + 1], p) >= 0;
    if (inside) return 0.0;
  }
  double best = 1e300;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[i + 1 == n ? 0 : i + 1];
    const Eigen::Vector2d ab = b - a;
    const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
    best = std::min(best, (a + t * ab - p).squaredNorm());
  }
  return std::sqrt(best);
}
}  // namespace

std::vector<uint8_t> projection_mask(const Projection& p) {
  std::vector<Eigen::Vector2d> corners;
  for (int c = 0; c < 16; ++c) {
    Vec4 x;
    for (int d = 0; d < 4; ++d) x[d] = (c >> d) & 1 ? 1.0 : -1.0;
    corners.push_back(p.texel_coords(x));
  }
  const auto hull = convex_hull(corners);
  const int R = p.res;
  std::vector<uint8_t> inside(R * R, 0), mask(R * R, 0);
  // A texel is "inside" when its centre lies within half a texel diagonal of the
  // hull, so thin (nearly degenerate) images still get a band of texels.
  for (int j = 0; j < R; ++j)
    for (int i = 0; i < R; ++i)
      inside[j * R + i] = hull_distance(hull, Eigen::Vector2d(i, j)) <= 1e-9 ? 1 : 0;
  // Plus the neighbours, so that bilinear reconstruction at the hull edge only
  // reads masked texels (thesis 3.2.4).
  for (int j = 0; j < R; ++j)
    for (int i = 0; i < R; ++i) {
      if (!inside[j * R + i]) continue;
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const int a = i + di, b = j + dj;
          if (a >= 0 && a < R && b >= 0 && b < R) mask[b * R + a] = 1;
        }
    }
  // Cells that the hull crosses but that contain no texel centre (thin images):
  // mark the 4 corners of every cell the hull's points can reach.
  for (int j = 0; j + 1 < R; ++j)
    for (int i = 0; i + 1 < R; ++i) {
      if (hull_distance(hull, Eigen::Vector2d(i + 0.5, j + 0.5)) <= 0.7072) {
        mask[j * R + i] = mask[j * R + i + 1] = mask[(j + 1) * R + i] = mask[(j + 1) * R + i + 1] = 1;
      }
    }
  return mask;
}

Bilinear bilinear(const Eigen::Vector2d& s, int res) {
  const double x = std::clamp(s.x(), 0.0, double(res - 1));
  const double y = std::clamp(s.y(), 0.0, double(res - 1));
  int i = std::min(static_cast<int>(x), res - 2);
  int j = std::min(static_cast<int>(y), res - 2);
  const double a = x - i, b = y - j;
  Bilinear w;
  w.idx = {j * res + i, j * res + i + 1, (j + 1) * res + i, (j + 1) * res + i + 1};
  w.w = {(1 - a) * (1 - b), a * (1 - b), (1 - a) * b, a * b};
  return w;
}

Projection projection_first_pair(Parameterization param, int res) {
  Projection p;
  p.param = param;
  p.res = res;
  p.P << 1, 0, 0, 0, 0, 1, 0, 0;
  return p;
}

Projection projection_second_pair(Parameterization param, int res) {
  Projection p;
  p.param = param;
  p.res = res;
  p.P << 0, 0, 1, 0, 0, 0, 0, 1;
  return p;
}

}  // namespace bf
