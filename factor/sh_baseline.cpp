// SH-K and SH-R baselines (see sh_baseline.h).
#include "factor/sh_baseline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "factor/isotropy.h"
#include "factor/metrics.h"
#include "factor/projection.h"
#include "solvers/parallel.h"
#include "solvers/quadrature.h"
#include "solvers/sh.h"
#include "solvers/sh_rotation.h"
#include "solvers/cancel.h"
#include "solvers/option_error.h"

namespace bf {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void require_brdf_value(const Brdf& brdf, const Rgb& f, const char* who) {
  if (!f.isFinite().all() || (f < 0.0).any())
    throw std::invalid_argument(std::string(who) + ": " + brdf.to_string() +
                                " returned a negative or non-finite value");
}
}  // namespace

// ================================================================ SH-K

int ShkOptions::auto_theta_nodes() const {
  return theta_nodes > 0 ? theta_nodes : std::max(2 * order + 2, 24);
}
int ShkOptions::auto_phi_nodes() const {
  return phi_nodes > 0 ? phi_nodes : std::max(4 * order + 4, 48);
}

void ShkOptions::validate() const {
  if (order < 0 || order > kMaxOrder)
    throw OptionError("order", "sh-k: order: expected 0.." + std::to_string(kMaxOrder) + ", found " +
                                std::to_string(order));
  if (view_res < 2 || view_res > kMaxTextureSize)
    throw OptionError("texture_size", "sh-k: texture_size: expected 2.." + std::to_string(kMaxTextureSize) +
                                ", found " + std::to_string(view_res));
  if (theta_nodes < 0 || theta_nodes > kMaxThetaNodes)
    throw OptionError("theta_nodes", "sh-k: theta_nodes: expected 0 (auto) or 1.." + std::to_string(kMaxThetaNodes) +
                                ", found " + std::to_string(theta_nodes));
  if (phi_nodes < 0 || phi_nodes > kMaxPhiNodes)
    throw OptionError("phi_nodes", "sh-k: phi_nodes: expected 0 (auto) or 1.." + std::to_string(kMaxPhiNodes) +
                                ", found " + std::to_string(phi_nodes));
  if (!(rim_inset > 0.0 && rim_inset <= 0.1))
    throw OptionError("rim_inset", "sh-k: rim_inset: expected 0 < rim_inset <= 0.1, found " +
                                std::to_string(rim_inset));
  if (!(min_cos > 0.0 && min_cos <= 1.0))
    throw OptionError("min_cos", "sh-k: min_cos: expected 0 < min_cos <= 1, found " +
                                std::to_string(min_cos));
}

ShkFactorization::ShkFactorization(const ShkOptions& opt, DiskGrid grid,
                                   std::array<Eigen::MatrixXd, 3> coeffs, double seconds)
    : opt_(opt), grid_(std::move(grid)), basis_(opt.order), coeffs_(std::move(coeffs)),
      seconds_(seconds) {
  for (int c = 0; c < 3; ++c) {
    const Eigen::Index cols = opt_.reduced ? Eigen::Index(opt_.view_res) : Eigen::Index(grid_.count());
    if (coeffs_[c].rows() != sh_count(opt_.order) || coeffs_[c].cols() != cols)
      throw std::invalid_argument("sh-k factorization: coefficient matrix is " +
                                  std::to_string(coeffs_[c].rows()) + " x " +
                                  std::to_string(coeffs_[c].cols()) + ", expected " +
                                  std::to_string(sh_count(opt_.order)) + " x " +
                                  std::to_string(cols));
    if (opt_.float_textures) coeffs_[c] = coeffs_[c].cast<float>().cast<double>();
  }
}

Eigen::MatrixXd ShkFactorization::coefficients_at(const Vec3& wo) const {
  if (opt_.reduced) {
    const Vec2 p = parabolic(wo);
    const int R = opt_.view_res;
    const double s = std::clamp(p.norm(), 0.0, 1.0) * (R - 1);
    const int j = std::min(int(s), R - 2);
    const double t = s - j;
    const double phi = std::atan2(p.y(), p.x());
    Eigen::MatrixXd out(sh_count(opt_.order), 3);
    for (int c = 0; c < 3; ++c) {
      out.col(c) = (1.0 - t) * coeffs_[c].col(j) + t * coeffs_[c].col(j + 1);
      sh_rotate_z(opt_.order, phi, out.col(c).data());
    }
    return out;
  }
  const Bilinear b = bilinear(grid_.coords(parabolic(wo)), grid_.res);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(sh_count(opt_.order), 3);
  for (int q = 0; q < 4; ++q) {
    const int a = grid_.slot[b.idx[q]];
    if (a < 0 || b.w[q] == 0.0) continue;
    for (int c = 0; c < 3; ++c) out.col(c) += b.w[q] * coeffs_[c].col(a);
  }
  return out;
}

Rgb ShkFactorization::eval_product(const Vec3& wi, const Vec3& wo) const {
  if (wo.z() <= 0.0) return Rgb::Zero();
  const Eigen::MatrixXd C = coefficients_at(wo);
  const Eigen::VectorXd y = basis_.eval(wi);
  const Eigen::Vector3d r = C.transpose() * y;
  return r.array();
}

Rgb ShkFactorization::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  return eval_product(wi, wo) / std::max(wi.z(), opt_.min_cos);
}

size_t ShkFactorization::storage_floats() const {
  return (opt_.reduced ? size_t(opt_.view_res) : grid_.count()) * size_t(sh_count(opt_.order)) * 3;
}

std::vector<double> ShkFactorization::texture(int c, int i) const {
  if (c < 0 || c > 2 || i < 0 || i >= sh_count(opt_.order))
    throw std::invalid_argument("sh-k: texture index out of range");
  std::vector<double> t(size_t(grid_.res) * grid_.res, 0.0);
  for (size_t a = 0; a < grid_.count(); ++a)
    t[grid_.texels[a]] = opt_.reduced ? coefficients_at(grid_.direction(grid_.texels[a], opt_.rim_inset))(i, c)
                                      : coeffs_[c](i, Eigen::Index(a));
  return t;
}

std::shared_ptr<ShkFactorization> ShkFactorization::truncated(int k) const {
  if (k < 0 || k > opt_.order)
    throw std::invalid_argument("sh-k: truncation order must be in 0.." +
                                std::to_string(opt_.order) + ", found " + std::to_string(k));
  std::array<Eigen::MatrixXd, 3> c;
  for (int ch = 0; ch < 3; ++ch) c[ch] = coeffs_[ch].topRows(sh_count(k));
  ShkOptions o = opt_;
  o.order = k;
  // Keep the quadrature of the parent fit (described as such).
  o.theta_nodes = opt_.auto_theta_nodes();
  o.phi_nodes = opt_.auto_phi_nodes();
  auto f = std::make_shared<ShkFactorization>(o, grid_, std::move(c), seconds_);
  f->min_product = min_product;
  f->negative_fraction = negative_fraction;
  return f;
}

std::string ShkFactorization::to_string() const {
  std::ostringstream os;
  os << "sh-k(order " << opt_.order << ", " << sh_count(opt_.order) << " coefficients, view ";
  if (opt_.reduced) os << grid_.res << " radial (isotropic, phi_v = 0)";
  else os << grid_.res << "x" << grid_.res;
  os << ")";
  return os.str();
}

nlohmann::json ShkFactorization::describe() const {
  nlohmann::json j;
  j["method"] = "sh-k";
  j["represents"] = "f*(wi, wo) = f(wi, wo) * max(0, wi.z); score on cos_rmse";
  j["form"] =
      "f*_c(wi, wo) = sum_i c_ci(p(wo)) * y_i(wi), c read by bilinear interpolation over the "
      "view grid; eval returns f* / max(wi.z, min_cos)";
  j["sh_convention"] =
      "real orthonormal SH without Condon-Shortley phase, index l*(l+1)+m; y_{l,m>0} = "
      "sqrt(2) p_lm cos(m phi), y_{l,-m} = sqrt(2) p_lm sin(m phi); see solvers/sh.h";
  j["order"] = opt_.order;
  j["coefficients"] = sh_count(opt_.order);
  j["view_resolution"] = grid_.res;
  j["view_map"] = "parabolic p(wo) = (x, y) / (1 + z)";
  j["texel_coords"] = "s = (p + 1) / 2 * (resolution - 1); texel (i, j) at s = (i, j), index j * resolution + i";
  j["view_texels"] = opt_.reduced ? size_t(opt_.view_res) : grid_.count();
  j["reduced"] = opt_.reduced;
  if (opt_.reduced)
    j["reduced_form"] =
        "isotropic: column j holds c at the view of parabolic radius r_j = j/(resolution-1) (pulled in to "
        "1 - rim_inset), azimuth 0; c(wo) = D(R_z(phi_v)) [linear interpolation in r = |p(wo)|], "
        "D(R_z(a)): c'_lm = c_lm cos(m a) - c_l,-m sin(m a), c'_l,-m = c_lm sin(m a) + c_l,-m cos(m a), m > 0";
  j["rim_inset"] = opt_.rim_inset;
  j["quadrature"] = {{"theta_nodes", opt_.auto_theta_nodes()},
                     {"phi_nodes", opt_.auto_phi_nodes()},
                     {"rule", "Gauss-Legendre in cos(theta) on [0,1] x uniform phi"}};
  j["min_cos"] = opt_.min_cos;
  j["min_product"] = min_product;
  j["negative_fraction"] = negative_fraction;
  j["float_textures"] = opt_.float_textures;
  j["storage_floats"] = storage_floats();
  j["seconds"] = seconds_;
  return j;
}

std::shared_ptr<ShkFactorization> fit_shk(const Brdf& brdf, const ShkOptions& opt) {
  opt.validate();
  const auto t0 = std::chrono::steady_clock::now();
  const DiskGrid grid = DiskGrid::make(opt.view_res);
  const SphereRule rule = sphere_rule(opt.auto_theta_nodes(), opt.auto_phi_nodes(), 0.0, 1.0);
  const ShBasis basis(opt.order);
  const int n = basis.size();
  const Eigen::Index Nq = Eigen::Index(rule.size());
  Eigen::MatrixXd Y(Nq, n), Yw(Nq, n);
  {
    Eigen::VectorXd y(n);
    for (Eigen::Index k = 0; k < Nq; ++k) {
      basis.eval(rule.dir[k], y.data());
      Y.row(k) = y.transpose();
      Yw.row(k) = rule.w[k] * y.transpose();
    }
  }
  if (opt.reduced) {
    const IsotropyResult iso = test_isotropy(brdf);
    if (!iso.isotropic)
      throw std::invalid_argument("sh-k: reduced (isotropic) storage asked for " + brdf.to_string() +
                                  ", but it is anisotropic: f changes by " + std::to_string(iso.max_rel_change) +
                                  " (relative) when wi, wo rotate together about the normal (tolerance 1e-3)");
  }
  // View directions: the masked grid texels, or the phi_v = 0 radii (reduced).
  std::vector<Vec3> views;
  std::vector<uint8_t> view_inside;
  if (opt.reduced) {
    for (int j = 0; j < opt.view_res; ++j) {
      const double r = std::min(double(j) / (opt.view_res - 1), 1.0 - opt.rim_inset);
      views.push_back(parabolic_inverse(Vec2(r, 0.0)));
      view_inside.push_back(1);
    }
  } else {
    for (size_t a = 0; a < grid.count(); ++a) {
      const int texel = grid.texels[a];
      views.push_back(grid.direction(texel, opt.rim_inset));
      view_inside.push_back(grid.point(texel).norm() <= 1.0 + 1e-12);
    }
  }
  const Eigen::Index T = Eigen::Index(views.size());
  std::array<Eigen::MatrixXd, 3> coeffs;
  for (auto& C : coeffs) C.resize(n, T);
  // Views in chunks (so the sample matrix stays small at high resolutions),
  // chunks in parallel; each writes only its own coefficient columns.
  const Eigen::Index chunk = 64;
  const Eigen::Index n_chunks = (T + chunk - 1) / chunk;
  double min_product = std::numeric_limits<double>::infinity();
  double negatives = 0, checked = 0;
  std::mutex stats_mutex;
  parallel_for(n_chunks, [&](int64_t k0, int64_t k1) {
    Eigen::MatrixXd Fm(Nq, 3 * chunk);
    double local_min = std::numeric_limits<double>::infinity(), local_neg = 0, local_checked = 0;
    for (int64_t kc = k0; kc < k1; ++kc) {
      check_cancel();
      const Eigen::Index t0v = Eigen::Index(kc) * chunk;
      const Eigen::Index nb = std::min(chunk, T - t0v);
      std::vector<uint8_t> inside(nb);
      for (Eigen::Index b = 0; b < nb; ++b) {
        inside[b] = view_inside[t0v + b];
        const Vec3& v = views[t0v + b];
        for (Eigen::Index k = 0; k < Nq; ++k) {
          const Vec3& s = rule.dir[k];
          const Rgb f = brdf.eval(s, v);
          require_brdf_value(brdf, f, "sh-k");
          for (int c = 0; c < 3; ++c) Fm(k, 3 * b + c) = f[c] * s.z();
        }
      }
      const Eigen::MatrixXd C = Yw.transpose() * Fm.leftCols(3 * nb);  // n x 3nb
      for (Eigen::Index b = 0; b < nb; ++b)
        for (int c = 0; c < 3; ++c) coeffs[c].col(t0v + b) = C.col(3 * b + c);
      // Ringing check at the quadrature nodes.
      const Eigen::MatrixXd R = Y * C;  // Nq x 3nb
      for (Eigen::Index b = 0; b < nb; ++b) {
        if (!inside[b]) continue;
        const auto block = R.middleCols(3 * b, 3);
        local_min = std::min(local_min, block.minCoeff());
        local_neg += double((block.array() < 0.0).count());
        local_checked += double(block.size());
      }
    }
    std::lock_guard<std::mutex> lock(stats_mutex);
    min_product = std::min(min_product, local_min);
    negatives += local_neg;
    checked += local_checked;
  });
  auto fit = std::make_shared<ShkFactorization>(opt, grid, std::move(coeffs), seconds_since(t0));
  fit->min_product = std::isfinite(min_product) ? min_product : 0.0;
  fit->negative_fraction = checked > 0 ? negatives / checked : 0.0;
  return fit;
}

SizeChoice select_shk_order(const Brdf& brdf, const SampleSet& samples, const ShkOptions& base,
                            const Tolerance& tol, int max_order) {
  tol.validate();
  if (max_order < 0 || max_order > 100)
    throw std::invalid_argument("sh-k: max order: expected 0..100, found " + std::to_string(max_order));
  const auto t0 = std::chrono::steady_clock::now();
  const LogTransform lt = LogTransform::of(samples);
  SizeChoice ch;
  ch.method = "sh-k";
  ch.knob = "order";
  ch.metric = tol.metric;
  double best = std::numeric_limits<double>::infinity();
  int scored = -1;  // orders <= scored are done
  int F = std::min(2, max_order);
  while (true) {
    ShkOptions opt = base;
    opt.order = F;
    const auto fit = fit_shk(brdf, opt);
    for (int k = scored + 1; k <= F; ++k) {
      auto fk = k == F ? fit : fit->truncated(k);
      const double e = tol.error_of(*fk, samples, lt);
      ch.tried.push_back({k, -1, e});
      if (e < best) {
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
        ch.seconds = seconds_since(t0);
        return ch;
      }
    }
    scored = F;
    if (F == max_order) break;
    F = std::min(max_order, 2 * F + 2);
  }
  ch.seconds = seconds_since(t0);
  return ch;
}

// ================================================================ SH-R

int ShrOptions::auto_theta_i_nodes() const {
  return theta_i_nodes > 0 ? theta_i_nodes : std::max(4 * max_order + 4, 160);
}
int ShrOptions::auto_theta_o_nodes() const {
  return theta_o_nodes > 0 ? theta_o_nodes : std::max(8 * max_view_order + 8, 96);
}
int ShrOptions::auto_phi_nodes() const {
  return phi_nodes > 0 ? phi_nodes : std::max(4 * max_order + 4, 128);
}

void ShrOptions::validate() const {
  if (max_order < 0 || max_order > kMaxOrder)
    throw OptionError("max_order", "sh-r: max_order: expected 0.." + std::to_string(kMaxOrder) + ", found " +
                                std::to_string(max_order));
  if (max_view_order < 0 || max_view_order > kMaxViewOrder)
    throw OptionError("max_view_order", "sh-r: max_view_order: expected 0.." + std::to_string(kMaxViewOrder) +
                                ", found " + std::to_string(max_view_order));
  if ((order >= 0) != (view_order >= 0))
    throw std::invalid_argument("sh-r: order and view_order are set together (fixed orders) or "
                                "both left at -1 (orders from energy_eps); found order=" +
                                std::to_string(order) + ", view_order=" + std::to_string(view_order));
  if (order > max_order)
    throw OptionError("order", "sh-r: order: expected <= max_order (" + std::to_string(max_order) +
                                "), found " + std::to_string(order));
  if (view_order > max_view_order)
    throw OptionError("view_order", "sh-r: view_order: expected <= max_view_order (" +
                                std::to_string(max_view_order) + "), found " +
                                std::to_string(view_order));
  if (!(energy_eps > 0.0 && energy_eps < 1.0))
    throw OptionError("energy_eps", "sh-r: energy_eps: expected 0 < eps < 1, found " +
                                std::to_string(energy_eps));
  for (auto [name, v] : {std::pair{"theta_i_nodes", theta_i_nodes}, std::pair{"theta_o_nodes", theta_o_nodes},
                         std::pair{"phi_nodes", phi_nodes}})
    if (v < 0 || v > kMaxNodes)
      throw std::invalid_argument(std::string("sh-r: ") + name + ": expected 0 (auto) or 1.." +
                                  std::to_string(kMaxNodes) + ", found " + std::to_string(v));
  if (!(min_cos > 0.0 && min_cos <= 1.0))
    throw OptionError("min_cos", "sh-r: min_cos: expected 0 < min_cos <= 1, found " +
                                std::to_string(min_cos));
}

double ShrCoefficients::accuracy(int f, int p) const {
  f = std::min(f, F);
  p = std::min(p, P);
  double worst = 1.0;
  for (int c = 0; c < 3; ++c) {
    if (!(energy[c] > 0.0)) continue;
    double e = 0.0;
    for (int l = 0; l <= f; ++l)
      for (int pp = 0; pp <= p; ++pp)
        for (int q = 0; q <= std::min(l, pp); ++q) {
          const double r = at(c, l, pp, q);
          e += (q == 0 ? 1.0 : 2.0) * r * r;
        }
    worst = std::min(worst, e / energy[c]);
  }
  return worst;
}

namespace {
// Local (normal-frame) L and V of the reparameterized point (notes §1.3.2):
// R = z, V' = (sin to, 0, cos to), N = (sin(to/2), 0, cos(to/2)),
// tangent t = (cos(to/2), 0, -sin(to/2)), bitangent (0, 1, 0).
void reparam_to_local(double cti, double sti, double cphi, double sphi, double half_c,
                      double half_s, Vec3& L, Vec3& V) {
  const Vec3 Lr(sti * cphi, -sti * sphi, cti);
  L = Vec3(Lr.x() * half_c - Lr.z() * half_s, Lr.y(), Lr.x() * half_s + Lr.z() * half_c);
  V = Vec3(half_s, 0.0, half_c);
}
}  // namespace

ShrCoefficients shr_coefficients(const Brdf& brdf, const ShrOptions& opt) {
  opt.validate();
  if (!brdf.isotropic())
    throw std::invalid_argument("sh-r: " + brdf.to_string() +
                                " is anisotropic; SH-R represents isotropic BRDFs only (use sh-k)");
  const auto t0 = std::chrono::steady_clock::now();
  const int F = opt.max_order, P = opt.max_view_order;
  const GaussLegendre gi = gauss_legendre(opt.auto_theta_i_nodes());
  const GaussLegendre go = gauss_legendre(opt.auto_theta_o_nodes());
  const int nphi = opt.auto_phi_nodes();
  const int ni = int(gi.x.size()), no = int(go.x.size());
  const double wphi = 2.0 * M_PI / nphi;
  std::vector<double> cphi(nphi), sphi(nphi);
  for (int k = 0; k < nphi; ++k) {
    const double phi = wphi * (k + 0.5);
    cphi[k] = std::cos(phi);
    sphi[k] = std::sin(phi);
  }
  // cos(q phi_k) table.
  Eigen::MatrixXd cosq(P + 1, nphi);
  for (int q = 0; q <= P; ++q)
    for (int k = 0; k < nphi; ++k) cosq(q, k) = std::cos(q * wphi * (k + 0.5));
  // Step 1 (notes §1.3.3): rq[c](i, o * (P+1) + q) = sum_phi w_phi rho_hat cos(q phi).
  std::array<Eigen::MatrixXd, 3> rq;
  for (auto& m : rq) m = Eigen::MatrixXd::Zero(ni, no * (P + 1));
  Rgb energy = Rgb::Zero();
  std::mutex energy_mutex;
  // theta_o nodes in parallel; each writes only its own columns of rq.
  parallel_for(no, [&](int64_t o0, int64_t o1) {
    std::vector<double> vals(3 * size_t(nphi));
    Rgb local_energy = Rgb::Zero();
    for (int o = int(o0); o < int(o1); ++o) {
      check_cancel();
      const double cto = go.x[o];
      const double half_c = std::sqrt(0.5 * (1.0 + cto)), half_s = std::sqrt(0.5 * (1.0 - cto));
      for (int i = 0; i < ni; ++i) {
        const double cti = gi.x[i], sti = std::sqrt(std::max(0.0, (1.0 - cti) * (1.0 + cti)));
        for (int k = 0; k < nphi; ++k) {
          Vec3 L, V;
          reparam_to_local(cti, sti, cphi[k], sphi[k], half_c, half_s, L, V);
          Rgb f = Rgb::Zero();
          if (L.z() > 0.0) {
            f = brdf.eval(L, V);
            require_brdf_value(brdf, f, "sh-r");
            f *= L.z();
          }
          local_energy += (2.0 * M_PI * gi.w[i] * go.w[o] * wphi) * f * f;
          for (int c = 0; c < 3; ++c) vals[3 * k + c] = f[c];
        }
        for (int c = 0; c < 3; ++c)
          for (int q = 0; q <= P; ++q) {
            double s = 0.0;
            for (int k = 0; k < nphi; ++k) s += cosq(q, k) * vals[3 * k + c];
            rq[c](i, o * (P + 1) + q) = s * wphi;
          }
      }
    }
    std::lock_guard<std::mutex> lock(energy_mutex);
    energy += local_energy;
  });
  // Steps 2 and 3: project on p_pq(cos to) and p_lq(cos ti).
  std::vector<double> col(std::max(F, P) + 1);
  Eigen::MatrixXd Po(no, (P + 1) * (P + 1));  // Po(o, p*(P+1)+q) = w_o p_pq(x_o)
  Po.setZero();
  for (int o = 0; o < no; ++o)
    for (int q = 0; q <= P; ++q) {
      legendre_normalized_column(q, P, go.x[o], col.data());
      for (int p = q; p <= P; ++p) Po(o, p * (P + 1) + q) = go.w[o] * col[p - q];
    }
  Eigen::MatrixXd Pi(ni, (F + 1) * (P + 1));  // Pi(i, l*(P+1)+q) = w_i p_lq(x_i)
  Pi.setZero();
  for (int i = 0; i < ni; ++i)
    for (int q = 0; q <= std::min(P, F); ++q) {
      legendre_normalized_column(q, F, gi.x[i], col.data());
      for (int l = q; l <= F; ++l) Pi(i, l * (P + 1) + q) = gi.w[i] * col[l - q];
    }
  ShrCoefficients out;
  out.F = F;
  out.P = P;
  out.energy = energy;
  for (int c = 0; c < 3; ++c) {
    out.rho[c].assign(size_t(F + 1) * (P + 1) * (P + 1), 0.0);
    for (int q = 0; q <= std::min(P, F); ++q) {
      // A(i, p) = sum_o rq(i, o, q) w_o p_pq(x_o)
      Eigen::MatrixXd A = Eigen::MatrixXd::Zero(ni, P + 1);
      for (int o = 0; o < no; ++o)
        for (int p = q; p <= P; ++p) A.col(p) += rq[c].col(o * (P + 1) + q) * Po(o, p * (P + 1) + q);
      for (int l = q; l <= F; ++l) {
        const Eigen::VectorXd wl = Pi.col(l * (P + 1) + q);
        for (int p = q; p <= P; ++p)
          out.rho[c][out.index(l, p, q)] = 2.0 * M_PI * wl.dot(A.col(p));
      }
    }
  }
  out.seconds = seconds_since(t0);
  return out;
}

ShrOrders select_shr_orders(const ShrCoefficients& coeffs, double eps) {
  if (!(eps > 0.0 && eps < 1.0))
    throw std::invalid_argument("sh-r: energy_eps: expected 0 < eps < 1, found " + std::to_string(eps));
  ShrOrders r;
  r.F = coeffs.F;
  r.P = coeffs.P;
  for (int p = 0; p <= coeffs.P; ++p)
    if (coeffs.accuracy(coeffs.F, p) >= 1.0 - eps) {
      r.P = p;
      r.reached = true;
      break;
    }
  if (r.reached)
    for (int f = 0; f <= coeffs.F; ++f)
      if (coeffs.accuracy(f, r.P) >= 1.0 - eps) {
        r.F = f;
        break;
      }
  r.accuracy = coeffs.accuracy(r.F, r.P);
  return r;
}

size_t shr_coefficient_count(int F, int P) {
  size_t n = 0;
  for (int p = 0; p <= P; ++p) {
    for (int l = 0; l <= F; ++l) n += size_t(std::min(l, p)) + 1;
  }
  return n;
}

ShrFactorization::ShrFactorization(const ShrCoefficients& all, int F, int P, double min_cos,
                                   double eps_used, double seconds)
    : F_(F), P_(P), min_cos_(min_cos), eps_used_(eps_used), seconds_(seconds),
      energy_(all.energy) {
  if (F < 0 || P < 0 || F > all.F || P > all.P)
    throw std::invalid_argument("sh-r: orders (" + std::to_string(F) + ", " + std::to_string(P) +
                                ") exceed the computed (" + std::to_string(all.F) + ", " +
                                std::to_string(all.P) + ")");
  for (int c = 0; c < 3; ++c) {
    rho_[c].assign(size_t(F + 1) * (P + 1) * (P + 1), 0.0);
    for (int l = 0; l <= F; ++l)
      for (int p = 0; p <= P; ++p)
        for (int q = 0; q <= std::min(l, p); ++q)
          rho_[c][(l * (P + 1) + p) * (P + 1) + q] = all.at(c, l, p, q);
  }
  accuracy_ = all.accuracy(F, P);
}

double ShrFactorization::coefficient(int c, int l, int p, int q) const {
  if (c < 0 || c > 2 || l < 0 || l > F_ || p < 0 || p > P_ || q < 0 || q > std::min(l, p))
    throw std::invalid_argument("sh-r: coefficient index out of range");
  return rho_[c][(l * (P_ + 1) + p) * (P_ + 1) + q];
}

Rgb ShrFactorization::eval_product(const Vec3& wi, const Vec3& wo) const {
  if (wo.z() <= 0.0) return Rgb::Zero();
  // Reflection vector R of wo about n = z; to = angle(R, wo) = 2 theta_v.
  const Vec3 R(-wo.x(), -wo.y(), wo.z());
  const double cto = std::clamp(2.0 * wo.z() * wo.z() - 1.0, -1.0, 1.0);
  const double cti = std::clamp(R.dot(wi), -1.0, 1.0);
  const Vec3 Lp = wi - cti * R, Vp = wo - R.dot(wo) * R;
  const double nl = Lp.norm(), nv = Vp.norm();
  // phi is irrelevant when either in-plane part vanishes (every q > 0 term is 0 there).
  const double cphi = (nl > 1e-300 && nv > 1e-300) ? std::clamp(Lp.dot(Vp) / (nl * nv), -1.0, 1.0) : 1.0;
  const int Q = std::min(F_, P_);
  std::vector<double> cq(Q + 1);
  cq[0] = 1.0;
  if (Q >= 1) cq[1] = cphi;
  for (int q = 2; q <= Q; ++q) cq[q] = 2.0 * cphi * cq[q - 1] - cq[q - 2];  // Chebyshev
  std::vector<double> pi(F_ + 1), po(P_ + 1);
  Rgb sum = Rgb::Zero();
  for (int q = 0; q <= Q; ++q) {
    legendre_normalized_column(q, F_, cti, pi.data());
    legendre_normalized_column(q, P_, cto, po.data());
    const double Uq = q == 0 ? 1.0 : 2.0;
    for (int l = q; l <= F_; ++l)
      for (int p = q; p <= P_; ++p) {
        const double b = Uq * pi[l - q] * po[p - q] * cq[q];
        for (int c = 0; c < 3; ++c) sum[c] += b * rho_[c][(l * (P_ + 1) + p) * (P_ + 1) + q];
      }
  }
  return sum;
}

Rgb ShrFactorization::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  return eval_product(wi, wo) / std::max(wi.z(), min_cos_);
}

size_t ShrFactorization::storage_floats() const { return shr_coefficient_count(F_, P_) * 3; }

std::string ShrFactorization::to_string() const {
  std::ostringstream os;
  os << "sh-r(F " << F_ << ", P " << P_ << ", accuracy " << accuracy_ << ")";
  return os.str();
}

nlohmann::json ShrFactorization::describe() const {
  nlohmann::json j;
  j["method"] = "sh-r";
  j["represents"] = "rho_hat = f(wi, wo) * max(0, wi.z), reparameterized about R = reflect(wo); score on cos_rmse";
  j["form"] =
      "rho_hat_c = sum_{l<=F, p<=P, 0<=q<=min(l,p)} U_q rho_clpq p_lq(R.wi) p_pq(cos 2theta_v) "
      "cos(q phi), U_0 = 1, U_q>0 = 2; phi = angle between the parts of wi and wo normal to R; "
      "p_lq normalized Legendre (solvers/sh.h); eval returns rho_hat / max(wi.z, min_cos)";
  j["order"] = F_;
  j["view_order"] = P_;
  j["energy_eps"] = eps_used_;
  j["accuracy"] = accuracy_;
  j["energy"] = {energy_[0], energy_[1], energy_[2]};
  j["coefficients"] = shr_coefficient_count(F_, P_);
  j["coefficient_index"] = "(l * (P+1) + p) * (P+1) + q, zero where q > min(l, p)";
  j["min_cos"] = min_cos_;
  j["storage_floats"] = storage_floats();
  j["seconds"] = seconds_;
  return j;
}

std::shared_ptr<ShrFactorization> fit_shr(const Brdf& brdf, const ShrOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const ShrCoefficients all = shr_coefficients(brdf, opt);
  int F = opt.order, P = opt.view_order;
  if (F < 0) {
    const ShrOrders o = select_shr_orders(all, opt.energy_eps);
    F = o.F;
    P = o.P;
  }
  return std::make_shared<ShrFactorization>(all, F, P, opt.min_cos, opt.energy_eps,
                                            seconds_since(t0));
}

SizeChoice select_shr_orders_by_metric(const Brdf& brdf, const SampleSet& samples,
                                       const ShrOptions& opt_in, const Tolerance& tol) {
  tol.validate();
  const auto t0 = std::chrono::steady_clock::now();
  ShrOptions opt = opt_in;
  opt.order = opt.view_order = -1;
  const ShrCoefficients all = shr_coefficients(brdf, opt);
  const LogTransform lt = LogTransform::of(samples);
  SizeChoice ch;
  ch.method = "sh-r";
  ch.knob = "order";
  ch.metric = tol.metric;
  std::shared_ptr<ShrFactorization> best;
  double best_e = std::numeric_limits<double>::infinity();
  auto score = [&](int F, int P) {
    auto f = std::make_shared<ShrFactorization>(all, F, P, opt.min_cos, 0.0, 0.0);
    const double e = tol.error_of(*f, samples, lt);
    ch.tried.push_back({F, P, e});
    if (e < best_e) {
      best_e = e;
      best = f;
    }
    return std::pair{e, f};
  };
  int P = -1;
  for (int p = 0; p <= all.P; ++p) {
    const auto [e, f] = score(all.F, p);
    if (e <= tol.value) {
      P = p;
      ch.value = all.F;
      ch.view_order = p;
      ch.error = e;
      ch.result = f;
      ch.reached = true;
      break;
    }
  }
  if (P >= 0) {
    int lo = 0, hi = all.F;  // (hi, P) reaches tol
    while (lo < hi) {
      const int mid = (lo + hi) / 2;
      const auto [e, f] = score(mid, P);
      if (e <= tol.value) {
        hi = mid;
        ch.value = mid;
        ch.error = e;
        ch.result = f;
      } else {
        lo = mid + 1;
      }
    }
  } else {
    ch.value = best->order();
    ch.view_order = best->view_order();
    ch.error = best_e;
    ch.result = best;
  }
  ch.seconds = seconds_since(t0);
  return ch;
}

// ================================================================ zonal (1D)

int ZonalCoefficients::order_for_energy(double eps) const {
  double acc = 0.0;
  for (size_t l = 0; l < rho.size(); ++l) {
    acc += rho[l] * rho[l];
    if (acc >= (1.0 - eps) * energy) return int(l);
  }
  return -1;
}

ZonalCoefficients zonal_coefficients(const std::function<double(double)>& rho_hat, int order,
                                     int nodes, double u_min) {
  if (order < 0) throw std::invalid_argument("zonal: order must be >= 0, found " + std::to_string(order));
  if (!(u_min >= -1.0 && u_min < 1.0))
    throw std::invalid_argument("zonal: u_min: expected -1 <= u_min < 1, found " + std::to_string(u_min));
  const GaussLegendre g = gauss_legendre(nodes, u_min, 1.0);
  ZonalCoefficients z;
  z.rho.assign(order + 1, 0.0);
  std::vector<double> col(order + 1);
  for (size_t k = 0; k < g.x.size(); ++k) {
    const double r = rho_hat(g.x[k]);
    z.energy += 2.0 * M_PI * g.w[k] * r * r;
    legendre_normalized_column(0, order, g.x[k], col.data());
    for (int l = 0; l <= order; ++l) z.rho[l] += 2.0 * M_PI * g.w[k] * r * col[l];
  }
  return z;
}

}  // namespace bf
