// Environment lighting, band limits, lit shading and the SHRM (see lighting.h).
#include "factor/lighting.h"

#include "brdfs/file_check.h"
#include "factor/image_io.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace bf {

namespace fs = std::filesystem;

namespace {
const char* const kChannelName[3] = {"R", "G", "B"};
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
}  // namespace

// ================================================================ lat-long maps

Vec3 LatLongMap::direction(int x, int y, int width, int height) {
  const double theta = M_PI * (y + 0.5) / height, phi = 2.0 * M_PI * (x + 0.5) / width;
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

LatLongMap read_latlong(const std::string& path) {
  check_regular_file(path, kMaxImageFileBytes, "environment map");
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".exr" && ext != ".hdr" && ext != ".pic")
    throw std::invalid_argument(path + ": environment map: expected a .exr or .hdr (Radiance) file, found '" + ext +
                                "'");
  // R, G, B (or one grey channel) as floats, row 0 = theta 0 (the zenith).
  const FloatImage img = ext == ".exr" ? read_exr_rgb(path, true) : read_hdr(path);
  const int W = img.width, H = img.height;
  if (W != 2 * H)
    throw std::invalid_argument(path + ": environment map: expected a lat-long map with width = 2 x height, found " +
                                std::to_string(W) + "x" + std::to_string(H));
  if (H < 4)
    throw std::invalid_argument(path + ": environment map: expected at least 8x4 texels, found " +
                                std::to_string(W) + "x" + std::to_string(H));
  const int used = 3;
  const std::vector<float>& px = img.pixels;
  LatLongMap m;
  m.width = W;
  m.height = H;
  m.path = path;
  m.texels.resize(size_t(W) * H);
  for (size_t k = 0; k < m.texels.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      const int src = used == 3 ? c : 0;
      const float v = px[k * used + src];
      if (!std::isfinite(v) || v < 0.0f)
        throw std::invalid_argument(path + ": environment map: texel (" + std::to_string(k % W) + ", " +
                                    std::to_string(k / W) + ") channel " + kChannelName[src] +
                                    ": expected a finite radiance >= 0, found " + num(v));
      m.texels[k][c] = v;
    }
  }
  return m;
}

void write_latlong(const std::string& path, const LatLongMap& map) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  FloatImage img;
  img.width = map.width;
  img.height = map.height;
  img.channel_names = {"R", "G", "B"};
  img.pixels.resize(map.texels.size() * 3);
  for (size_t k = 0; k < map.texels.size(); ++k)
    for (int c = 0; c < 3; ++c) img.pixels[3 * k + c] = float(map.texels[k][c]);
  if (ext == ".exr")
    write_exr(path, img);
  else if (ext == ".hdr" || ext == ".pic")
    write_hdr(path, img);
  else
    throw std::runtime_error(path + ": environment map: expected a .exr or .hdr file name, found '" + ext + "'");
}

LatLongMap make_latlong(int width, int height, const std::function<Rgb(const Vec3&)>& radiance) {
  if (height < 1 || width != 2 * height)
    throw std::invalid_argument("make_latlong: expected width = 2 x height >= 2, found " + std::to_string(width) +
                                "x" + std::to_string(height));
  LatLongMap m;
  m.width = width;
  m.height = height;
  m.texels.resize(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) m.texels[size_t(y) * width + x] = radiance(LatLongMap::direction(x, y, width, height));
  return m;
}

std::vector<double> fejer_weights(int n) {
  if (n < 1) throw std::invalid_argument("fejer_weights: n must be >= 1, found " + std::to_string(n));
  std::vector<double> w(n);
  for (int j = 0; j < n; ++j) {
    const double th = M_PI * (j + 0.5) / n;
    double s = 0.0;
    for (int k = 1; k <= n / 2; ++k) s += std::cos(2.0 * k * th) / (4.0 * k * k - 1.0);
    w[j] = 2.0 / n * (1.0 - 2.0 * s);
  }
  return w;
}

// ================================================================ SH lighting

int ShLighting::order_for_energy(double eps) const {
  for (size_t l = 0; l < fraction.size(); ++l)
    if (fraction[l] >= 1.0 - eps) return int(l);
  return -1;
}

ShLighting ShLighting::truncated(int k) const {
  if (k < 0 || k > order)
    throw std::invalid_argument("lighting: truncation order must be in 0.." + std::to_string(order) + ", found " +
                                std::to_string(k));
  ShLighting t = *this;
  t.order = k;
  for (int c = 0; c < 3; ++c) t.coeffs[c] = coeffs[c].head(sh_count(k));
  t.fraction.resize(size_t(k) + 1);
  return t;
}

Rgb ShLighting::radiance(const Vec3& w) const {
  const Eigen::VectorXd y = sh_eval(order, w);
  return Rgb(coeffs[0].dot(y), coeffs[1].dot(y), coeffs[2].dot(y));
}

nlohmann::json ShLighting::describe() const {
  nlohmann::json j;
  j["source"] = source;
  j["order"] = order;
  j["band_limit"] = band_limit;
  j["band_eps"] = band_eps;
  j["band_limit_reached"] = band_limit_reached;
  j["energy"] = {energy[0], energy[1], energy[2]};
  j["fraction"] = fraction;
  j["coefficients"] = {std::vector<double>(coeffs[0].data(), coeffs[0].data() + coeffs[0].size()),
                       std::vector<double>(coeffs[1].data(), coeffs[1].data() + coeffs[1].size()),
                       std::vector<double>(coeffs[2].data(), coeffs[2].data() + coeffs[2].size())};
  j["sh_convention"] = "real orthonormal SH without Condon-Shortley phase, index l*(l+1)+m (solvers/sh.h)";
  return j;
}

namespace {
void fill_fractions(ShLighting& L) {
  L.fraction.assign(size_t(L.order) + 1, 0.0);
  std::array<double, 3> acc{0, 0, 0};
  for (int l = 0; l <= L.order; ++l) {
    double worst = 1.0;
    for (int c = 0; c < 3; ++c) {
      acc[c] += L.coeffs[c].segment(l * l, 2 * l + 1).squaredNorm();
      if (L.energy[c] > 0.0) worst = std::min(worst, acc[c] / L.energy[c]);
    }
    L.fraction[l] = worst;
  }
}
}  // namespace

ShLighting project_latlong(const LatLongMap& map, int max_order) {
  const int W = map.width, H = map.height;
  const std::string who = map.path.empty() ? std::string("environment map") : map.path;
  if (W != 2 * H || H < 1 || map.texels.size() != size_t(W) * H)
    throw std::invalid_argument(who + ": expected a lat-long map with width = 2 x height, found " + std::to_string(W) +
                                "x" + std::to_string(H));
  if (max_order < 0 || max_order > H - 1 || 2 * max_order > W - 1)
    throw std::invalid_argument(who + ": projection order: expected 0.." + std::to_string(std::min(H - 1, (W - 1) / 2)) +
                                " for a " + std::to_string(W) + "x" + std::to_string(H) + " map, found " +
                                std::to_string(max_order));
  const int F = max_order;
  const std::vector<double> wz = fejer_weights(H);
  const double dphi = 2.0 * M_PI / W;
  ShLighting L;
  L.order = F;
  for (auto& c : L.coeffs) c = Eigen::VectorXd::Zero(sh_count(F));
  std::vector<double> cosm(size_t(W) * (F + 1)), sinm(size_t(W) * (F + 1));
  for (int x = 0; x < W; ++x)
    for (int m = 0; m <= F; ++m) {
      const double phi = dphi * (x + 0.5);
      cosm[size_t(x) * (F + 1) + m] = std::cos(m * phi);
      sinm[size_t(x) * (F + 1) + m] = std::sin(m * phi);
    }
  std::vector<double> p(size_t(legendre_index(F, F)) + 1);
  Eigen::MatrixXd A(F + 1, 3), B(F + 1, 3);
  for (int y = 0; y < H; ++y) {
    const double theta = M_PI * (y + 0.5) / H;
    const double z = std::cos(theta);
    const double w = wz[y] * dphi;
    A.setZero();
    B.setZero();
    for (int x = 0; x < W; ++x) {
      const Rgb& v = map.at(x, y);
      for (int c = 0; c < 3; ++c) L.energy[c] += w * v[c] * v[c];
      for (int m = 0; m <= F; ++m)
        for (int c = 0; c < 3; ++c) {
          A(m, c) += v[c] * cosm[size_t(x) * (F + 1) + m];
          B(m, c) += v[c] * sinm[size_t(x) * (F + 1) + m];
        }
    }
    legendre_normalized(F, z, p.data());
    for (int l = 0; l <= F; ++l)
      for (int c = 0; c < 3; ++c) {
        L.coeffs[c][sh_index(l, 0)] += w * p[legendre_index(l, 0)] * A(0, c);
        for (int m = 1; m <= l; ++m) {
          const double pm = std::sqrt(2.0) * w * p[legendre_index(l, m)];
          L.coeffs[c][sh_index(l, m)] += pm * A(m, c);
          L.coeffs[c][sh_index(l, -m)] += pm * B(m, c);
        }
      }
  }
  L.source = map.path.empty() ? "env:(memory)" : "env:" + map.path;
  fill_fractions(L);
  return L;
}

ShLighting environment_lighting(const LatLongMap& map, double eps, int max_order) {
  if (!(eps > 0.0 && eps < 1.0))
    throw std::invalid_argument((map.path.empty() ? std::string("environment map") : map.path) +
                                ": band-limit eps: expected 0 < eps < 1, found " + num(eps));
  const ShLighting full = project_latlong(map, max_order);
  int L = full.order_for_energy(eps);
  const bool reached = L >= 0;
  if (!reached) L = full.order;
  ShLighting out = full.truncated(L);
  out.band_limit = L;
  out.band_eps = eps;
  out.band_limit_reached = reached;
  return out;
}

ShLighting directional_lighting(const Vec3& d, const Rgb& irradiance, int order) {
  if (order < 0 || order > 200)
    throw std::invalid_argument("directional lighting: order: expected 0..200, found " + std::to_string(order));
  if (!(d.norm() > 0.0) || !d.allFinite())
    throw std::invalid_argument("directional lighting: direction must be finite and non-zero");
  ShLighting L;
  L.order = order;
  const Eigen::VectorXd y = sh_eval(order, d.normalized());
  for (int c = 0; c < 3; ++c) {
    L.coeffs[c] = irradiance[c] * y;
    L.energy[c] = L.coeffs[c].squaredNorm();
  }
  L.source = "directional";
  L.band_limit = order;
  fill_fractions(L);
  return L;
}

// ================================================================ lit shading

LitShader::LitShader(std::shared_ptr<const ShLighting> lighting, int nodes_theta, int nodes_phi)
    : lighting_(std::move(lighting)), rot_(lighting_ ? lighting_->order : 0) {
  if (!lighting_) throw std::invalid_argument("lit shader: no lighting");
  const int F = lighting_->order;
  nz_ = nodes_theta > 0 ? nodes_theta : std::max(16, F + 8);
  nphi_ = nodes_phi > 0 ? nodes_phi : 2 * nz_;
  rule_ = sphere_rule(nz_, nphi_, 0.0, 1.0);
  plm_.resize(nz_, legendre_index(F, F) + 1);
  std::vector<double> p(size_t(legendre_index(F, F)) + 1);
  for (int j = 0; j < nz_; ++j) {
    legendre_normalized(F, rule_.dir[size_t(j) * nphi_].z(), p.data());
    for (size_t i = 0; i < p.size(); ++i) plm_(j, Eigen::Index(i)) = p[i];
  }
  cosm_.resize(nphi_, F + 1);
  sinm_.resize(nphi_, F + 1);
  for (int k = 0; k < nphi_; ++k)
    for (int m = 0; m <= F; ++m) {
      const double phi = 2.0 * M_PI / nphi_ * (k + 0.5);
      cosm_(k, m) = std::cos(m * phi);
      sinm_(k, m) = std::sin(m * phi);
    }
}

std::array<Eigen::VectorXd, 3> LitShader::local_coefficients(const Eigen::Matrix3d& M) const {
  std::array<Eigen::VectorXd, 3> c = lighting_->coeffs;
  const Eigen::Vector3d e = ShFastRotator::euler_zyz(M.transpose());
  for (int ch = 0; ch < 3; ++ch) rot_.rotate_zyz(e[0], e[1], e[2], c[ch].data());
  return c;
}

Rgb LitShader::shade(const Brdf& f, const Vec3& n, const Vec3& t, const Vec3& b, const Vec3& wo_world,
                     size_t* nonfinite) const {
  Eigen::Matrix3d M;
  M.col(0) = t;
  M.col(1) = b;
  M.col(2) = n;
  const Vec3 wo = M.transpose() * wo_world;
  if (wo.z() <= 0.0) return Rgb::Zero();
  const auto c = local_coefficients(M);
  const int F = lighting_->order;
  const double r2 = std::sqrt(2.0);
  Eigen::MatrixXd a(2 * F + 1, 3);  // row F + m: sum_l c_lm p_lm (x sqrt 2 for m != 0)
  Rgb out = Rgb::Zero();
  for (int j = 0; j < nz_; ++j) {
    a.setZero();
    for (int l = 0; l <= F; ++l)
      for (int m = -l; m <= l; ++m) {
        const double p = plm_(j, legendre_index(l, std::abs(m))) * (m == 0 ? 1.0 : r2);
        for (int ch = 0; ch < 3; ++ch) a(F + m, ch) += c[ch][sh_index(l, m)] * p;
      }
    for (int k = 0; k < nphi_; ++k) {
      const size_t node = size_t(j) * nphi_ + k;
      const Vec3& s = rule_.dir[node];
      Rgb Ls(a(F, 0), a(F, 1), a(F, 2));
      for (int m = 1; m <= F; ++m)
        for (int ch = 0; ch < 3; ++ch) Ls[ch] += a(F + m, ch) * cosm_(k, m) + a(F - m, ch) * sinm_(k, m);
      Rgb v = f.eval(s, wo);
      if (!v.isFinite().all()) {
        if (nonfinite) ++*nonfinite;
        continue;
      }
      out += rule_.w[node] * s.z() * Ls * v;
    }
  }
  return out;
}

// ================================================================ SHRM

namespace {
int pq_index(int p, int q) { return p * p + p + q; }
double lambda(int l) { return std::sqrt(4.0 * M_PI / (2.0 * l + 1.0)); }
}  // namespace

Shrm::Shrm(const ShrFactorization& shr, const ShLighting& lighting)
    : F_(std::min(shr.order(), lighting.order)), P_(shr.view_order()),
      rot_(std::min(shr.order(), lighting.order)) {
  const auto t0 = std::chrono::steady_clock::now();
  npq_ = sh_count(P_);
  for (int c = 0; c < 3; ++c) {
    B_[c].assign(size_t(sh_count(F_)) * npq_, 0.0);
    for (int l = 0; l <= F_; ++l)
      for (int m = -l; m <= l; ++m)
        for (int p = 0; p <= P_; ++p)
          for (int q = -std::min(l, p); q <= std::min(l, p); ++q)
            B_[c][size_t(sh_index(l, m)) * npq_ + pq_index(p, q)] =
                lambda(l) * shr.coefficient(c, l, p, std::abs(q)) * lighting.coeffs[c][sh_index(l, m)];
  }
  seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Bs_.resize(sh_count(F_), 3 * npq_);
  for (int c = 0; c < 3; ++c)
    for (int l = 0; l <= F_; ++l)
      for (int m = -l; m <= l; ++m)
        for (int pq = 0; pq < npq_; ++pq)
          Bs_(sh_index(l, m), c * npq_ + pq) = B_[c][size_t(sh_index(l, m)) * npq_ + pq] / lambda(l);
}

size_t Shrm::coefficient_count() const {
  size_t n = 0;
  for (int l = 0; l <= F_; ++l)
    for (int p = 0; p <= P_; ++p) n += size_t(2 * l + 1) * (2 * std::min(l, p) + 1);
  return n;
}

double Shrm::coefficient(int c, int l, int m, int p, int q) const {
  if (c < 0 || c > 2 || l < 0 || l > F_ || std::abs(m) > l || p < 0 || p > P_ || std::abs(q) > p)
    throw std::invalid_argument("shrm: coefficient index out of range");
  return B_[c][size_t(sh_index(l, m)) * npq_ + pq_index(p, q)];
}

Rgb Shrm::eval_angles(double alpha, double beta, double theta_o, double phi_o) const {
  const Vec3 V(std::sin(theta_o) * std::cos(phi_o), std::sin(theta_o) * std::sin(phi_o), std::cos(theta_o));
  const Eigen::VectorXd ypq = sh_eval(P_, V);
  // Every (channel, p, q) column rotated at once by D(M^T), M = Rz(beta) Ry(alpha):
  // M^T = Ry(-alpha) Rz(-beta); then B_pq = sum_l (D(M^T) column)_{l, q}.
  Eigen::MatrixXd C = Bs_;
  rot_.rotate_zyz(0.0, -alpha, -beta, C);
  Rgb out = Rgb::Zero();
  for (int c = 0; c < 3; ++c)
    for (int p = 0; p <= P_; ++p)
      for (int q = -p; q <= p; ++q) {
        const int pq = pq_index(p, q);
        double Bpq = 0.0;
        for (int l = std::abs(q); l <= F_; ++l) Bpq += C(sh_index(l, q), c * npq_ + pq);
        out[c] += Bpq * ypq[pq];
      }
  return out;
}

Rgb Shrm::eval(const Vec3& R, const Vec3& v) const {
  const double alpha = std::acos(std::clamp(R.z(), -1.0, 1.0));
  const double beta = std::atan2(R.y(), R.x());
  // V in the frame M = Rz(beta) Ry(alpha): M^T v.
  const double ca = std::cos(alpha), sa = std::sin(alpha), cb = std::cos(beta), sb = std::sin(beta);
  const Vec3 u(cb * v.x() + sb * v.y(), -sb * v.x() + cb * v.y(), v.z());  // Rz(-beta) v
  const Vec3 V(ca * u.x() - sa * u.z(), u.y(), sa * u.x() + ca * u.z());    // Ry(-alpha) u
  const double theta_o = std::acos(std::clamp(V.z(), -1.0, 1.0));
  const double phi_o = std::atan2(V.y(), V.x());
  return eval_angles(alpha, beta, theta_o, phi_o);
}

Rgb Shrm::shade(const Vec3& n, const Vec3& v) const {
  const double nv = n.dot(v);
  if (nv <= 0.0) return Rgb::Zero();
  const Vec3 R = 2.0 * nv * n - v;
  return eval(R.normalized(), v);
}

nlohmann::json Shrm::to_json() const {
  nlohmann::json j;
  j["method"] = "shrm";
  j["form"] =
      "B_c(alpha, beta, theta_o, phi_o) = sum_{p<=P, |q|<=p} B_cpq(alpha, beta) y_pq(theta_o, phi_o), "
      "B_cpq(alpha, beta) = sum_{l<=F, |m|<=l} B_clmpq / Lambda_l * D^l_qm(M^T), M = Rz(beta) Ry(alpha), "
      "Lambda_l = sqrt(4 pi / (2l+1)); (alpha, beta) = reflection vector, (theta_o, phi_o) = view in frame M";
  j["definition"] = "B_clmpq = Lambda_l rho_c,l,p,|q| L_clm (rho from sh-r, L the lighting's SH coefficients)";
  j["sh_convention"] = "real orthonormal SH without Condon-Shortley phase, index l*(l+1)+m (solvers/sh.h)";
  j["order"] = F_;
  j["view_order"] = P_;
  j["coefficients_per_channel"] = coefficient_count();
  j["storage_floats"] = storage_floats();
  j["index"] = "(l*(l+1)+m) * (P+1)^2 + p*(p+1)+q; entries with |q| > min(l, p) are 0 and not counted";
  nlohmann::json ch = nlohmann::json::array();
  for (int c = 0; c < 3; ++c) ch.push_back(B_[c]);
  j["B"] = ch;
  j["seconds"] = seconds_;
  return j;
}

}  // namespace bf
