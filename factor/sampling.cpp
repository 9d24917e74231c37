// Importance sampling: the tabulated sampler of f cos theta_i (every BRDF),
// the Cook-Torrance model's own sampler, cosine sampling. docs/design.md,
// "Importance sampling".
#include "factor/sampling.h"
#include "factor/sampling_export.h"

#include <algorithm>
#include <cmath>

#include "brdfs/models.h"
#include "factor/model_fit.h"
#include "solvers/option_error.h"

namespace bf {

namespace {

constexpr double kPi = M_PI;
constexpr double kHalfPi = 0.5 * M_PI;
constexpr double kTwoPi = 2.0 * M_PI;

double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// u in [0, 1) after remapping: never 1 (a float CDF step can round it there).
double clamp_u(double u) { return std::min(std::max(u, 0.0), std::nextafter(1.0, 0.0)); }

Vec3 cosine_dir(double u1, double u2) {
  const double r = std::sqrt(u1), phi = kTwoPi * u2;
  return Vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1)));
}
double cosine_pdf(const Vec3& wi) { return wi.z() > 0 ? wi.z() / kPi : 0.0; }

bool above(const Vec3& w) { return w.z() > 0 && std::isfinite(w.z()) && std::isfinite(w.x()) && std::isfinite(w.y()); }

class CosineSampler final : public BrdfSampler {
 public:
  DirectionSample sample(const Vec3& wo, double u1, double u2) const override {
    if (!above(wo)) return {};
    const Vec3 wi = cosine_dir(clamp_u(u1), clamp_u(u2));
    return {wi, cosine_pdf(wi)};
  }
  double pdf(const Vec3& wi, const Vec3& wo) const override {
    return above(wo) ? cosine_pdf(wi) : 0.0;
  }
  size_t storage_floats() const override { return 0; }
  std::string method() const override { return "cosine"; }
};

// Index of the last entry of cdf[0..n] (n + 1 values, cdf[0] = 0, cdf[n] = 1)
// that is <= u, in [0, n - 1]; skips steps of zero width.
int find_interval(const float* cdf, int n, double u) {
  int lo = 0, hi = n;  // cdf[lo] <= u < cdf[hi]
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (static_cast<double>(cdf[mid]) <= u) lo = mid; else hi = mid;
  }
  return lo;
}

// The unit direction of w's projection on the xy plane, (1, 0) on the pole:
// the x axis of the frame in which wi's azimuth is relative to wo's.
Vec3 azimuth_axis(const Vec3& w) {
  const double r = std::hypot(w.x(), w.y());
  return r > 0 ? Vec3(w.x() / r, w.y() / r, 0.0) : Vec3(1.0, 0.0, 0.0);
}

// 1 - cos theta of a unit direction, precise also near the normal.
double one_minus_cos(const Vec3& w) {
  return w.z() >= 0.5 ? (w.x() * w.x() + w.y() * w.y()) / (1.0 + w.z()) : 1.0 - w.z();
}

// Index k in [0, n) of the wedge [2 pi k / n, 2 pi (k + 1) / n) holding the
// angle of (x, y) (not both 0): a guess from atan2, corrected by the sign of
// the cross product with the wedge's edges (so the GLSL, whose atan is an
// approximation, finds the same wedge).
int wedge(double x, double y, int n) {
  double a = std::atan2(y, x);
  if (a < 0) a += kTwoPi;
  int k = static_cast<int>(a / kTwoPi * n);
  k = ((k % n) + n) % n;
  for (int it = 0; it < 2; ++it) {
    const double e0 = k * kTwoPi / n, e1 = (k + 1) * kTwoPi / n;
    if (std::cos(e0) * y - std::sin(e0) * x < 0) k = (k + n - 1) % n;
    else if (std::cos(e1) * y - std::sin(e1) * x >= 0) k = (k + 1) % n;
    else break;
  }
  return k;
}

class TabulatedSampler final : public BrdfSampler {
 public:
  explicit TabulatedSampler(SamplerTable t) : t_(std::move(t)) {
    const SamplerGeometry g = sampler_geometry(t_);
    view_cos_ = g.view_cos, row_omc_ = g.row_omc;
  }

  DirectionSample sample(const Vec3& wo, double u1, double u2) const override {
    if (!above(wo)) return {};
    u1 = clamp_u(u1), u2 = clamp_u(u2);
    const Mix m = mix(wo);
    if (u1 < m.w_cos) {
      const Vec3 wi = cosine_dir(clamp_u(u1 / m.w_cos), u2);
      return {wi, pdf_mix(m, wi, wo)};
    }
    u1 -= m.w_cos;
    int v = m.va;
    double wv = m.w_a;
    if (u1 >= m.w_a && m.w_b > 0) u1 -= m.w_a, v = m.vb, wv = m.w_b;
    u1 = clamp_u(u1 / wv);
    const int T = t_.theta_bins, P = t_.phi_bins;
    const float* rc = &t_.row_cdf[static_cast<size_t>(v) * (T + 1)];
    const int r = find_interval(rc, T, u1);
    const double v1 = clamp_u((u1 - rc[r]) / (static_cast<double>(rc[r + 1]) - rc[r]));
    const float* cc = &t_.col_cdf[(static_cast<size_t>(v) * T + r) * (P + 1)];
    const int c = find_interval(cc, P, u2);
    const double v2 = clamp_u((u2 - cc[c]) / (static_cast<double>(cc[c + 1]) - cc[c]));
    // 1 - cos theta_i, uniform in the row (precise near the normal too).
    const double oa = row_omc_[r], ob = row_omc_[r + 1];
    const double omc = oa + (ob - oa) * v1, ct = 1.0 - omc;
    const double st = std::sqrt(std::max(0.0, omc * (2.0 - omc)));
    const double phi = (c + v2) * kTwoPi / P;  // relative to wo's azimuth
    const Vec3 ex = azimuth_axis(wo), ey(-ex.y(), ex.x(), 0.0);
    const double cp = std::cos(phi), sp = std::sin(phi);
    const Vec3 wi(st * (cp * ex.x() + sp * ey.x()), st * (cp * ex.y() + sp * ey.y()), ct);
    // The density at wi in the cell it was drawn from (a recomputed cell can
    // differ on the cell's edge by rounding).
    double p = m.w_cos * cosine_pdf(wi);
    if (m.w_a > 0) p += m.w_a * cell_pdf(m.va, r, c);
    if (m.w_b > 0) p += m.w_b * cell_pdf(m.vb, r, c);
    return {wi, wi.z() > 0 ? p : 0.0};
  }

  double pdf(const Vec3& wi, const Vec3& wo) const override {
    if (!above(wo)) return 0.0;
    return pdf_mix(mix(wo), wi, wo);
  }
  size_t storage_floats() const override { return t_.row_cdf.size() + t_.col_cdf.size(); }
  std::string method() const override { return "tabulated"; }
  const SamplerTable& table() const { return t_; }

 private:
  struct Mix {
    int va = 0, vb = 0;
    double w_cos = 1, w_a = 0, w_b = 0;
  };
  // Which view bins' tables, with which weights: linear in cos theta_o
  // between the cosines of the two nearest bin centres (clamped at both
  // ends), nearest phi_o bin; an empty table's weight goes to the cosine lobe.
  Mix mix(const Vec3& wo) const {
    const int V = t_.view_bins, VP = t_.view_phi_bins;
    const double z = wo.z();
    int a = 0, b = 0;
    double t = 0;
    if (z >= view_cos_[0]) {
      a = b = 0;
    } else if (z <= view_cos_[V - 1]) {
      a = b = V - 1;
    } else {
      // view_cos_ decreases: the last centre with cos >= z.
      int lo = 0, hi = V - 1;  // view_cos_[lo] > z > view_cos_[hi]
      while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        if (view_cos_[mid] >= z) lo = mid; else hi = mid;
      }
      a = lo, b = hi;
      t = (view_cos_[a] - z) / (view_cos_[a] - view_cos_[b]);
    }
    int vp = 0;
    if (VP > 1 && (wo.x() != 0 || wo.y() != 0)) {
      // Nearest bin centre 2 pi k / VP: the wedge of width 2 pi / VP starting
      // half a bin earlier, i.e. wo's direction rotated by + pi / VP.
      const double h = kPi / VP, c = std::cos(h), s = std::sin(h);
      vp = wedge(c * wo.x() - s * wo.y(), s * wo.x() + c * wo.y(), VP);
    }
    Mix m;
    m.va = a * VP + vp, m.vb = b * VP + vp;
    const double rest = 1.0 - t_.cosine_fraction;
    const double wa = rest * (1.0 - t), wb = rest * t;
    m.w_a = t_.empty[m.va] ? 0.0 : wa;
    m.w_b = t_.empty[m.vb] ? 0.0 : wb;
    // cosine_fraction itself when both tables exist (not 1 - w_a - w_b: u1 is
    // compared with it, and that sum would round differently in float).
    m.w_cos = t_.cosine_fraction + (t_.empty[m.va] ? wa : 0.0) + (t_.empty[m.vb] ? wb : 0.0);
    return m;
  }
  // The table's density in cell (r, c) of view bin v.
  double cell_pdf(int v, int r, int c) const {
    const int T = t_.theta_bins, P = t_.phi_bins;
    const float* rc = &t_.row_cdf[static_cast<size_t>(v) * (T + 1)];
    const float* cc = &t_.col_cdf[(static_cast<size_t>(v) * T + r) * (P + 1)];
    const double prob = (static_cast<double>(rc[r + 1]) - rc[r]) * (static_cast<double>(cc[c + 1]) - cc[c]);
    return prob / ((row_omc_[r + 1] - row_omc_[r]) * kTwoPi / P);
  }
  // The cell of wi (above the horizon): theta row by comparing 1 - cos theta_i
  // with the rows' edges, azimuth cell relative to wo's.
  std::pair<int, int> cell_of(const Vec3& wi, const Vec3& wo) const {
    const int T = t_.theta_bins, P = t_.phi_bins;
    // row_omc_[r] <= omc < row_omc_[r + 1].
    const double omc = one_minus_cos(wi);
    int lo = 0, hi = T;
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      if (row_omc_[mid] <= omc) lo = mid; else hi = mid;
    }
    int c = 0;
    if (wi.x() != 0 || wi.y() != 0) {
      const Vec3 ex = azimuth_axis(wo);
      c = wedge(wi.x() * ex.x() + wi.y() * ex.y(), wi.y() * ex.x() - wi.x() * ex.y(), P);
    }
    return {lo, c};
  }
  double pdf_mix(const Mix& m, const Vec3& wi, const Vec3& wo) const {
    if (!above(wi)) return 0.0;
    double p = m.w_cos * cosine_pdf(wi);
    if (m.w_a > 0 || m.w_b > 0) {
      const auto [r, c] = cell_of(wi, wo);
      if (m.w_a > 0) p += m.w_a * cell_pdf(m.va, r, c);
      if (m.w_b > 0) p += m.w_b * cell_pdf(m.vb, r, c);
    }
    return p;
  }

  SamplerTable t_;
  std::vector<double> view_cos_, row_omc_;
};

// Cook-Torrance: a mixture of the cosine lobe (the diffuse term) and the
// Beckmann distribution of normals, h drawn with density D(h) cos theta_h and
// reflected about wo (pdf D cos theta_h / (4 wo.h)); a reflection below the
// horizon is no sample (pdf 0).
class BeckmannSampler final : public BrdfSampler {
 public:
  BeckmannSampler(double m, double w_cos) : m_(m), w_cos_(w_cos) {}
  DirectionSample sample(const Vec3& wo, double u1, double u2) const override {
    if (!above(wo)) return {};
    u1 = clamp_u(u1), u2 = clamp_u(u2);
    Vec3 wi;
    if (u1 < w_cos_) {
      wi = cosine_dir(clamp_u(u1 / w_cos_), u2);
    } else {
      const double v = clamp_u((u1 - w_cos_) / (1.0 - w_cos_));
      const double tan2 = -m_ * m_ * std::log1p(-v);
      const double ch = 1.0 / std::sqrt(1.0 + tan2), sh = std::sqrt(std::max(0.0, 1.0 - ch * ch));
      const double phi = kTwoPi * u2;
      const Vec3 h(sh * std::cos(phi), sh * std::sin(phi), ch);
      wi = 2.0 * wo.dot(h) * h - wo;
      if (!above(wi)) return {};
      wi.normalize();
    }
    return {wi, pdf(wi, wo)};
  }
  double pdf(const Vec3& wi, const Vec3& wo) const override {
    if (!above(wo) || !above(wi)) return 0.0;
    double p = w_cos_ * cosine_pdf(wi);
    const Vec3 s = wi + wo;
    const double len = s.norm();
    if (len > 0) {
      const Vec3 h = s / len;
      const double ch = h.z(), ch2 = ch * ch, m2 = m_ * m_;
      const double tan2 = std::max(0.0, 1.0 - ch2) / ch2;
      const double d = std::exp(-tan2 / m2) / (kPi * m2 * ch2 * ch2);
      const double od = wo.dot(h);
      if (od > 0) p += (1.0 - w_cos_) * d * ch / (4.0 * od);
    }
    return p;
  }
  size_t storage_floats() const override { return 2; }  // m and the cosine weight
  std::string method() const override { return "model"; }

 private:
  double m_, w_cos_;
};

std::shared_ptr<const BrdfSampler> model_sampler(const Brdf& f, const SamplerOptions& o) {
  const Brdf* b = &f;
  if (const auto* mf = dynamic_cast<const ModelFitFactorization*>(&f)) b = mf->result().brdf.get();
  const auto* ct = dynamic_cast<const CookTorrance*>(b);
  if (!ct) return nullptr;
  const CookTorranceParams& p = ct->params();
  // Weights by albedo: the diffuse term's is kd; the specular term's about
  // ks F(0) times the form's scale over the unit-normalized Foley form.
  double f0;
  if (p.fresnel == CookTorranceParams::Fresnel::Schlick) {
    f0 = luminance(p.f0);
  } else {
    const Rgb r = (p.eta - 1.0) / (p.eta + 1.0);
    f0 = luminance(r * r);
  }
  const double scale = p.form == CookTorranceParams::Form::Foley ? 1.0
                       : p.form == CookTorranceParams::Form::CookTorrance ? 4.0 : 4.0 / kPi;
  const double wd = std::max(0.0, luminance(p.kd)), ws = std::max(0.0, luminance(p.ks) * f0 * scale);
  double w_cos = wd + ws > 0 ? wd / (wd + ws) : 1.0;
  w_cos = std::min(std::max(w_cos, o.cosine_fraction), 1.0 - o.cosine_fraction);
  return std::make_shared<BeckmannSampler>(p.m, w_cos);
}

// Adds to cell[r * P + c] the integral of max(0, Y(f)) cos theta_i over
// the cell (r, c) of wi for wo at (theta_o, phi_o): cells relative to phi_o, a
// cell_samples^2 midpoint rule uniform in 1 - cos theta_i and phi_i.
void add_cell_weights(const Brdf& f, double to, double po, const SamplerGeometry& geo, int T, int P, int S,
                      std::vector<double>& cell) {
  const Vec3 wo(std::sin(to) * std::cos(po), std::sin(to) * std::sin(po), std::cos(to));
  for (int r = 0; r < T; ++r) {
    const double oa = geo.row_omc[r], ob = geo.row_omc[r + 1];
    for (int c = 0; c < P; ++c) {
      double sum = 0;
      for (int i = 0; i < S; ++i) {
        const double omc = oa + (ob - oa) * (i + 0.5) / S, ct = 1.0 - omc;
        const double st = std::sqrt(std::max(0.0, omc * (2.0 - omc)));
        for (int j = 0; j < S; ++j) {
          const double phi = po + (c + (j + 0.5) / S) * kTwoPi / P;
          const Vec3 wi(st * std::cos(phi), st * std::sin(phi), ct);
          const double y = luminance(f.eval(wi, wo));
          if (std::isfinite(y) && y > 0) sum += y * ct;
        }
      }
      // Solid angle of the cell: (ob - oa) 2 pi / P.
      cell[static_cast<size_t>(r) * P + c] += sum / (S * S) * (ob - oa) * kTwoPi / P;
    }
  }
}

// View azimuths averaged into the single table of a BRDF that does not say
// it is isotropic when view_phi_bins = 1.
constexpr int kIsoAzimuths = 8;

void require(bool ok, const char* field, const std::string& rule, double value) {
  if (!ok) {
    throw OptionError(field, std::string("sampler option ") + field + ": " + rule + ", found " +
                                 std::to_string(value));
  }
}

}  // namespace

void SamplerOptions::validate() const {
  require(view_bins >= 1 && view_bins <= 256, "view_bins", "an integer in [1, 256]", view_bins);
  require(theta_bins >= 2 && theta_bins <= 1024, "theta_bins", "an integer in [2, 1024]", theta_bins);
  require(phi_bins >= 2 && phi_bins <= 1024, "phi_bins", "an integer in [2, 1024]", phi_bins);
  require(view_phi_bins >= 0 && view_phi_bins <= 256, "view_phi_bins", "an integer in [0, 256]",
          view_phi_bins);
  // Used as float32 (as the GLSL export holds it), which must still be in (0, 1).
  require(std::isfinite(cosine_fraction) && static_cast<float>(cosine_fraction) > 0 &&
              static_cast<float>(cosine_fraction) < 1,
          "cosine_fraction", "a number in (0, 1) also as float32", cosine_fraction);
  require(cell_samples >= 1 && cell_samples <= 16, "cell_samples", "an integer in [1, 16]", cell_samples);
  if (method != "auto" && method != "tabulated") {
    throw OptionError("method", "sampler option method: \"auto\" or \"tabulated\", found \"" + method + "\"");
  }
}

std::shared_ptr<const BrdfSampler> cosine_sampler() {
  static const auto s = std::make_shared<const CosineSampler>();
  return s;
}

std::shared_ptr<const BrdfSampler> make_sampler(const Brdf& f, const SamplerOptions& o) {
  o.validate();
  if (o.method == "auto") {
    if (auto s = model_sampler(f, o)) return s;
  }
  SamplerTable t;
  t.view_bins = o.view_bins;
  t.view_phi_bins = o.view_phi_bins > 0 ? o.view_phi_bins : (f.isotropic() ? 1 : 16);
  t.theta_bins = o.theta_bins;
  t.phi_bins = o.phi_bins;
  // float32, as the GLSL export holds it (u1 is compared with it).
  t.cosine_fraction = static_cast<float>(o.cosine_fraction);
  const int V = t.view_bins * t.view_phi_bins, T = t.theta_bins, P = t.phi_bins, S = o.cell_samples;
  t.row_cdf.assign(static_cast<size_t>(V) * (T + 1), 0.0f);
  t.col_cdf.assign(static_cast<size_t>(V) * T * (P + 1), 0.0f);
  t.empty.assign(V, 1);
  std::vector<double> cell(static_cast<size_t>(T) * P), row(T);
  const SamplerGeometry geo = sampler_geometry(t);
  for (int vt = 0; vt < t.view_bins; ++vt) {
    for (int vp = 0; vp < t.view_phi_bins; ++vp) {
      const int v = vt * t.view_phi_bins + vp;
      // The bin centre: theta_o = (vt + 1/2) pi / (2 view_bins), phi_o = 2 pi vp / view_phi_bins.
      const double to = (vt + 0.5) * kHalfPi / t.view_bins, po = vp * kTwoPi / t.view_phi_bins;
      // A BRDF that does not say it is isotropic, given one azimuth bin: the
      // mean of f cos over kIsoAzimuths view azimuths (the best single table
      // of, e.g., a factorization of an isotropic BRDF).
      const int na = (t.view_phi_bins == 1 && !f.isotropic()) ? kIsoAzimuths : 1;
      std::fill(cell.begin(), cell.end(), 0.0);
      for (int k = 0; k < na; ++k) add_cell_weights(f, to, po + k * kTwoPi / na, geo, T, P, S, cell);
      double total = 0;
      for (int r = 0; r < T; ++r) {
        row[r] = 0;
        for (int c = 0; c < P; ++c) row[r] += cell[static_cast<size_t>(r) * P + c];
        total += row[r];
      }
      if (!(total > 0) || !std::isfinite(total)) continue;
      t.empty[v] = 0;
      float* rc = &t.row_cdf[static_cast<size_t>(v) * (T + 1)];
      double acc = 0;
      for (int r = 0; r < T; ++r) {
        rc[r] = static_cast<float>(acc / total);
        acc += row[r];
        float* cc = &t.col_cdf[(static_cast<size_t>(v) * T + r) * (P + 1)];
        double ac = 0;
        for (int c = 0; c < P; ++c) {
          // A row without weight gets a uniform conditional (never drawn).
          cc[c] = static_cast<float>(row[r] > 0 ? ac / row[r] : static_cast<double>(c) / P);
          ac += cell[static_cast<size_t>(r) * P + c];
        }
        cc[P] = 1.0f;
      }
      rc[T] = 1.0f;
    }
  }
  return std::make_shared<TabulatedSampler>(std::move(t));
}

SamplerGeometry sampler_geometry(const SamplerTable& t) {
  SamplerGeometry g;
  auto f32 = [](double v) { return static_cast<double>(static_cast<float>(v)); };
  for (int k = 0; k < t.view_bins; ++k) g.view_cos.push_back(f32(std::cos((k + 0.5) * kHalfPi / t.view_bins)));
  for (int r = 0; r <= t.theta_bins; ++r) {
    const double s = std::sin(r * kHalfPi / t.theta_bins / 2);
    g.row_omc.push_back(f32(2 * s * s));  // 1 - cos
  }
  g.row_omc.back() = 1.0;  // the horizon
  return g;
}

std::shared_ptr<const BrdfSampler> tabulated_sampler(SamplerTable t) {
  return std::make_shared<TabulatedSampler>(std::move(t));
}

const SamplerTable* sampler_table(const BrdfSampler& s) {
  const auto* t = dynamic_cast<const TabulatedSampler*>(&s);
  return t ? &t->table() : nullptr;
}

}  // namespace bf
