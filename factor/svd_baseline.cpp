// SVD baseline, the shared parabolic texel grid and rank selection (see svd_baseline.h).
#include "factor/svd_baseline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "factor/metrics.h"
#include "factor/projection.h"
#include "solvers/parallel.h"
#include "solvers/cancel.h"
#include "solvers/option_error.h"

namespace bf {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// w with its elevation raised to at least z_min (azimuth kept; straight down
// goes to azimuth 0), unit length.
Vec3 lift_above_horizon(const Vec3& w, double z_min) {
  if (w.z() >= z_min) return w;
  const double t = std::hypot(w.x(), w.y()), s = std::sqrt(1.0 - z_min * z_min);
  if (t < 1e-300) return Vec3(s, 0.0, z_min);
  return Vec3(w.x() * s / t, w.y() * s / t, z_min);
}
}  // namespace

// ---------------------------------------------------------------- DiskGrid

DiskGrid DiskGrid::make(int res) {
  if (res < 2 || res > 1024)
    throw std::invalid_argument("texture_size: expected 2..1024, found " + std::to_string(res));
  DiskGrid g;
  g.res = res;
  g.slot.assign(size_t(res) * res, -1);
  std::vector<uint8_t> mask(size_t(res) * res, 0);
  const double h = 2.0 / (res - 1);
  for (int j = 0; j + 1 < res; ++j)
    for (int i = 0; i + 1 < res; ++i) {
      // Closest point of the cell [x0, x0 + h] x [y0, y0 + h] to the origin.
      const double x0 = -1.0 + i * h, y0 = -1.0 + j * h;
      const double cx = std::clamp(0.0, x0, x0 + h), cy = std::clamp(0.0, y0, y0 + h);
      if (cx * cx + cy * cy <= 1.0)
        mask[j * res + i] = mask[j * res + i + 1] = mask[(j + 1) * res + i] =
            mask[(j + 1) * res + i + 1] = 1;
    }
  for (int t = 0; t < res * res; ++t)
    if (mask[t]) {
      g.slot[t] = int(g.texels.size());
      g.texels.push_back(t);
    }
  return g;
}

Vec2 DiskGrid::point(int texel) const {
  const double h = 2.0 / (res - 1);
  return Vec2(-1.0 + (texel % res) * h, -1.0 + (texel / res) * h);
}

Vec3 DiskGrid::direction(int texel, double rim_inset) const {
  Vec2 p = point(texel);
  const double r = p.norm(), rmax = 1.0 - rim_inset;
  if (r > rmax) p *= rmax / r;
  return parabolic_inverse(p);
}

Eigen::Vector2d DiskGrid::coords(const Vec2& p) const {
  return ((p.array() + 1.0) * (0.5 * (res - 1))).matrix();
}

// ---------------------------------------------------------------- options

void SvdOptions::validate() const {
  if (res < 2 || res > 256)
    throw OptionError("texture_size", "svd: texture_size: expected 2..256, found " + std::to_string(res));
  if (rank < 1) throw OptionError("terms", "svd: terms: expected >= 1, found " + std::to_string(rank));
  if (!(eps > 0.0 && eps <= 1.0))
    throw OptionError("eps", "svd: eps: expected 0 < eps <= 1, found " + std::to_string(eps));
  if (!(rim_inset >= 0.0 && rim_inset <= 0.5))
    throw OptionError("rim_inset", "svd: rim_inset: expected 0 (half a texel) or 0 < rim_inset <= 0.5, found " +
                                std::to_string(rim_inset));
  if (subtract_eps && !log)
    throw OptionError("svd", "svd: subtract_eps applies only to the log-space SVD (log = true)");
}

double SvdOptions::effective_rim_inset() const {
  return rim_inset > 0.0 ? rim_inset : std::min(0.5, 1.0 / std::max(1, res - 1));
}

// ---------------------------------------------------------------- tabulation

SvdTable tabulate_svd(const Brdf& brdf, const SvdOptions& opt) {
  opt.validate();
  const auto t0 = std::chrono::steady_clock::now();
  SvdTable t;
  t.param = opt.param;
  t.grid = DiskGrid::make(opt.res);
  t.log = opt.log;
  t.eps = opt.eps;
  const int n = int(t.grid.count());
  for (auto& M : t.M) M.resize(n, n);
  std::vector<Vec3> dir(n);
  std::vector<uint8_t> inside(n);
  const double inset = opt.effective_rim_inset();
  for (int k = 0; k < n; ++k) {
    dir[k] = t.grid.direction(t.grid.texels[k], inset);
    inside[k] = t.grid.point(t.grid.texels[k]).norm() <= 1.0 + 1e-12;
  }
  // The lowest elevation a texel direction has (the pulled-in rim).
  const double rr = 1.0 - inset, z_min = (1.0 - rr * rr) / (1.0 + rr * rr);
  // Columns in parallel; each chunk keeps its own sums for A.
  Rgb sum = Rgb::Zero();
  double count = 0;
  std::mutex sum_mutex;
  parallel_for(n, [&](int64_t c0, int64_t c1) {
    Rgb local_sum = Rgb::Zero();
    double local_count = 0;
    for (int c = int(c0); c < int(c1); ++c) {
      check_cancel();
      for (int r = 0; r < n; ++r) {
        Vec3 wi = dir[r], wo = dir[c];
        if (opt.param == Parameterization::HalfDiff) half_diff_inverse(dir[r], dir[c], wi, wo);
        const bool valid = wi.z() > 0.0 && wo.z() > 0.0;
        if (!valid && opt.extend_below_horizon) {
          wi = lift_above_horizon(wi, z_min);
          wo = lift_above_horizon(wo, z_min);
        }
        Rgb f = Rgb::Zero();
        if (wi.z() > 0.0 && wo.z() > 0.0) {
          f = brdf.eval(wi, wo);
          if (!f.isFinite().all() || (f < 0.0).any())
            throw std::invalid_argument("svd: " + brdf.to_string() +
                                        " returned a negative or non-finite value at texel pair (" +
                                        std::to_string(t.grid.texels[r]) + ", " +
                                        std::to_string(t.grid.texels[c]) + ")");
          if (valid && inside[r] && inside[c]) {
            local_sum += f;
            local_count += 1;
          }
        }
        for (int ch = 0; ch < 3; ++ch) t.M[ch](r, c) = f[ch];
      }
    }
    std::lock_guard<std::mutex> lock(sum_mutex);
    sum += local_sum;
    count += local_count;
  });
  if (opt.log) {
    if (count == 0) throw std::invalid_argument("svd: no tabulated pair lies in the domain");
    t.A = sum / count;
    for (int ch = 0; ch < 3; ++ch) {
      if (!(t.A[ch] > 0.0) || !std::isfinite(t.A[ch]))
        throw std::invalid_argument("svd: log = true but channel " + std::string(1, "rgb"[ch]) +
                                    " of " + brdf.to_string() + " has mean " + std::to_string(t.A[ch]) +
                                    (t.A[ch] == 0.0 ? " (an all-zero BRDF has no log)"
                                                    : " (outside the double range: rescale the BRDF)"));
      const double A = t.A[ch], bias = opt.eps * A;
      t.M[ch] = ((t.M[ch].array() + bias) / A).log().matrix();
    }
  }
  t.seconds = seconds_since(t0);
  return t;
}

// ---------------------------------------------------------------- factorization

SvdFactorization::SvdFactorization(const SvdOptions& opt, DiskGrid grid, Rgb A,
                                   std::array<TruncatedSvd, 3> svd, double seconds)
    : opt_(opt), grid_(std::move(grid)), svd_(std::move(svd)), A_(A), seconds_(seconds) {
  rank_ = svd_[0].rank();
  for (int c = 0; c < 3; ++c) {
    if (svd_[c].rank() != rank_ || svd_[c].U.rows() != Eigen::Index(grid_.count()) ||
        svd_[c].V.rows() != Eigen::Index(grid_.count()))
      throw std::invalid_argument("svd factorization: factor shapes do not match the grid");
    if (opt_.float_textures) {
      svd_[c].U = svd_[c].U.cast<float>().cast<double>();
      svd_[c].V = svd_[c].V.cast<float>().cast<double>();
      svd_[c].sigma = svd_[c].sigma.cast<float>().cast<double>();
    }
    negative_texels_ += size_t((svd_[c].U.array() < 0.0).count() + (svd_[c].V.array() < 0.0).count());
  }
  opt_.rank = rank_;
}

double SvdFactorization::term_sum(int c, const Bilinear& row, const Bilinear& col) const {
  const TruncatedSvd& s = svd_[c];
  double sum = 0.0;
  for (int k = 0; k < rank_; ++k) {
    double u = 0.0, v = 0.0;
    for (int q = 0; q < 4; ++q) {
      const int a = grid_.slot[row.idx[q]], b = grid_.slot[col.idx[q]];
      // Unmasked texels hold 0 (never read by points in the disk).
      if (a >= 0) u += row.w[q] * s.U(a, k);
      if (b >= 0) v += col.w[q] * s.V(b, k);
    }
    sum += s.sigma[k] * u * v;
  }
  return sum;
}

Rgb SvdFactorization::eval_raw(const Vec3& wi, const Vec3& wo) const {
  const Vec4 x = to_point(opt_.param, wi, wo);
  const Bilinear row = bilinear(grid_.coords(x.head<2>()), grid_.res);
  const Bilinear col = bilinear(grid_.coords(x.tail<2>()), grid_.res);
  Rgb r;
  for (int c = 0; c < 3; ++c) r[c] = term_sum(c, row, col);
  return r;
}

Rgb SvdFactorization::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  Rgb f = eval_raw(wi, wo);
  if (opt_.log) {
    f = A_ * f.exp();
    if (opt_.subtract_eps) f -= opt_.eps * A_;
  }
  return f.max(0.0).min(std::numeric_limits<double>::max());
}

size_t SvdFactorization::storage_floats() const {
  size_t n = size_t(rank_) * (2 * grid_.count()) * 3 + 3 * size_t(rank_);
  if (opt_.log) n += 4;
  return n;
}

double SvdFactorization::discarded_norm(int c) const {
  return eckart_young_error(svd_[c].sigma, rank_);
}

std::vector<double> SvdFactorization::row_texture(int c, int k) const {
  std::vector<double> t(size_t(grid_.res) * grid_.res, 0.0);
  for (size_t a = 0; a < grid_.count(); ++a) t[grid_.texels[a]] = svd_[c].U(Eigen::Index(a), k);
  return t;
}

std::vector<double> SvdFactorization::col_texture(int c, int k) const {
  std::vector<double> t(size_t(grid_.res) * grid_.res, 0.0);
  for (size_t a = 0; a < grid_.count(); ++a) t[grid_.texels[a]] = svd_[c].V(Eigen::Index(a), k);
  return t;
}

std::shared_ptr<SvdFactorization> SvdFactorization::truncated(int k) const {
  if (k < 1 || k > rank_)
    throw std::invalid_argument("svd: truncation rank must be in 1.." + std::to_string(rank_) +
                                ", found " + std::to_string(k));
  std::array<TruncatedSvd, 3> s;
  for (int c = 0; c < 3; ++c) {
    s[c].U = svd_[c].U.leftCols(k);
    s[c].V = svd_[c].V.leftCols(k);
    s[c].sigma = svd_[c].sigma;
  }
  SvdOptions o = opt_;
  o.rank = k;
  o.float_textures = false;  // already rounded if requested
  auto f = std::make_shared<SvdFactorization>(o, grid_, A_, std::move(s), seconds_);
  f->opt_.float_textures = opt_.float_textures;
  return f;
}

std::string SvdFactorization::to_string() const {
  std::ostringstream os;
  os << "svd(" << bf::to_string(opt_.param) << ", rank " << rank_ << ", " << grid_.res << "x"
     << grid_.res << (opt_.log ? ", log" : "") << ")";
  return os.str();
}

nlohmann::json SvdFactorization::describe() const {
  nlohmann::json j;
  j["method"] = "svd";
  j["parameterization"] = bf::to_string(opt_.param);
  j["form"] = opt_.log
                  ? "f_c = A_c * exp(sum_k sigma_ck * u_ck(s_row) * v_ck(s_col))" +
                        std::string(opt_.subtract_eps ? " - eps * A_c" : "") +
                        ", clamped at 0; u, v read by bilinear interpolation"
                  : "f_c = sum_k sigma_ck * u_ck(s_row) * v_ck(s_col), clamped at 0; u, v read "
                    "by bilinear interpolation";
  j["rows"] = opt_.param == Parameterization::WiWo ? "p(wi)" : "p(h)";
  j["cols"] = opt_.param == Parameterization::WiWo ? "p(wo)" : "p(d)";
  j["resolution"] = grid_.res;
  j["texel_coords"] = "s = (p + 1) / 2 * (resolution - 1); texel (i, j) at s = (i, j), index j * resolution + i";
  j["texels_per_texture"] = grid_.count();
  j["rim_inset"] = opt_.effective_rim_inset();
  if (opt_.param == Parameterization::HalfDiff) j["extend_below_horizon"] = opt_.extend_below_horizon;
  j["rank"] = rank_;
  j["log"] = opt_.log;
  if (opt_.log) {
    j["A"] = {A_[0], A_[1], A_[2]};
    j["eps"] = opt_.eps;
    j["subtract_eps"] = opt_.subtract_eps;
  }
  nlohmann::json sig = nlohmann::json::array(), disc = nlohmann::json::array();
  for (int c = 0; c < 3; ++c) {
    std::vector<double> s(svd_[c].sigma.data(), svd_[c].sigma.data() + rank_);
    sig.push_back(s);
    disc.push_back(discarded_norm(c));
  }
  j["sigma"] = sig;
  j["discarded_norm"] = disc;
  j["negative_texels"] = negative_texels_;
  j["float_textures"] = opt_.float_textures;
  j["storage_floats"] = storage_floats();
  j["seconds"] = seconds_;
  return j;
}

std::shared_ptr<SvdFactorization> fit_svd(const SvdTable& table, const SvdOptions& opt) {
  opt.validate();
  if (table.grid.res != opt.res || table.param != opt.param || table.log != opt.log)
    throw std::invalid_argument("svd: the table was built with different options (res, "
                                "parameterization or log) than the fit asks for");
  // A linear table whose largest value is subnormal cannot be factored and
  // evaluated without underflow to 0 or overflow of 1/value: a clear error.
  for (int c = 0; c < 3; ++c) {
    const double amax = table.M[c].cwiseAbs().maxCoeff();
    if (amax > 0.0 && amax < std::numeric_limits<double>::min())
      throw std::invalid_argument("svd: channel " + std::to_string(c) +
                                  " of the table is denormal (largest value " +
                                  std::to_string(amax) +
                                  "): rescale the BRDF or use log = true");
  }
  const auto t0 = std::chrono::steady_clock::now();
  std::array<TruncatedSvd, 3> s;
  for (int c = 0; c < 3; ++c) {
    check_cancel();  // one decomposition (seconds at large sizes) per channel
    s[c] = truncated_svd(table.M[c], opt.rank);
  }
  check_cancel();
  return std::make_shared<SvdFactorization>(opt, table.grid, table.A, std::move(s),
                                            table.seconds + seconds_since(t0));
}

std::shared_ptr<SvdFactorization> fit_svd(const Brdf& brdf, const SvdOptions& opt) {
  return fit_svd(tabulate_svd(brdf, opt), opt);
}

// ---------------------------------------------------------------- selection

double Tolerance::error_of(const Brdf& candidate, const SampleSet& samples, const LogTransform& lt) const {
  if (score) {
    const double e = score(candidate);
    return std::isfinite(e) ? e : 1e300;  // a non-finite score never reaches a target
  }
  return metric_value(evaluate_metrics(candidate, samples, lt), metric);
}

const std::vector<std::string>& external_metric_names() {
  static const std::vector<std::string> n = {"shade_rmse", "val_rel_mse", "val_cos_rmse", "val_max_ratio"};
  return n;
}

bool is_external_metric(const std::string& name) {
  const auto& n = external_metric_names();
  return std::find(n.begin(), n.end(), name) != n.end();
}

void Tolerance::validate() const {
  if (is_external_metric(metric)) {
    if (!score)
      throw OptionError("tolerance", "tolerance: metric: '" + metric +
                                         "' is scored outside the fit's samples and needs a scorer (the experiment "
                                         "runner supplies one), found none");
  } else {
    Metrics probe;
    metric_value(probe, metric);  // throws naming the accepted metrics
  }
  if (!(value > 0.0) || !std::isfinite(value))
    throw OptionError("tolerance", "tolerance: value: expected a finite number > 0, found " +
                                std::to_string(value));
}

SizeChoice select_svd_rank(const Brdf& brdf, const SampleSet& samples, const SvdOptions& base,
                           const Tolerance& tol, int max_rank) {
  tol.validate();
  if (max_rank < 1)
    throw std::invalid_argument("svd: max rank must be >= 1, found " + std::to_string(max_rank));
  const auto t0 = std::chrono::steady_clock::now();
  SvdOptions opt = base;
  opt.rank = max_rank;
  const auto full = fit_svd(brdf, opt);
  const LogTransform lt = LogTransform::of(samples);
  SizeChoice ch;
  ch.method = "svd";
  ch.knob = "terms";
  ch.metric = tol.metric;
  double best = std::numeric_limits<double>::infinity();
  for (int k = 1; k <= full->rank(); ++k) {
    auto fk = full->truncated(k);
    const double e = tol.error_of(*fk, samples, lt);
    ch.tried.push_back({k, -1, e});
    if (e < best || !ch.result) {
      best = e;
      ch.value = k;
      ch.error = e;
      ch.result = fk;
    }
    if (e <= tol.value) {
      ch.value = k;
      ch.error = e;
      ch.result = fk;
      ch.reached = true;
      break;
    }
  }
  ch.seconds = seconds_since(t0);
  return ch;
}

const std::vector<int>& default_texture_ladder() {
  static const std::vector<int> ladder = {8, 12, 16, 24, 32};
  return ladder;
}

void validate_texture_ladder(const std::vector<int>& ladder, int lo, int hi, const std::string& what) {
  if (ladder.empty()) throw std::invalid_argument(what + ": expected a non-empty list of resolutions, found []");
  for (size_t i = 0; i < ladder.size(); ++i) {
    if (ladder[i] < lo || ladder[i] > hi)
      throw std::invalid_argument(what + ": expected resolutions in " + std::to_string(lo) + ".." +
                                  std::to_string(hi) + ", found " + std::to_string(ladder[i]));
    if (i > 0 && ladder[i] <= ladder[i - 1])
      throw std::invalid_argument(what + ": expected strictly ascending resolutions, found " +
                                  std::to_string(ladder[i]) + " after " + std::to_string(ladder[i - 1]));
  }
}

SizeChoice select_svd_size(const Brdf& brdf, const SampleSet& samples, const SvdOptions& base,
                           const Tolerance& tol, int max_rank, const std::vector<int>& ladder) {
  validate_texture_ladder(ladder, 2, 256, "svd: texture_ladder");
  tol.validate();
  const auto t0 = std::chrono::steady_clock::now();
  SizeChoice best;
  best.error = std::numeric_limits<double>::infinity();
  std::vector<SizeTrial> tried;
  for (int res : ladder) {
    SvdOptions o = base;
    o.res = res;
    SizeChoice c = select_svd_rank(brdf, samples, o, tol, max_rank);
    for (SizeTrial t : c.tried) {
      t.texture_size = res;
      tried.push_back(t);
    }
    c.texture_size = res;
    if (c.reached || !best.result || c.error < best.error) best = std::move(c);
    if (best.reached) break;
  }
  best.tried = std::move(tried);
  best.seconds = seconds_since(t0);
  return best;
}

}  // namespace bf
