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

// The azimuth of w in [0, 2 pi).
double azimuth(const Vec3& w) {
  if (w.x() == 0 && w.y() == 0) return 0.0;  // (atan2(-0, -0) is -pi)
  double p = std::atan2(w.y(), w.x());
  if (p < 0) p += kTwoPi;
  return p >= kTwoPi ? 0.0 : p;
}

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

class TabulatedSampler final : public BrdfSampler {
 public:
  explicit TabulatedSampler(SamplerTable t) : t_(std::move(t)) {}

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
    const double ca = std::cos(r * kHalfPi / T), cb = std::cos((r + 1) * kHalfPi / T);
    const double ct = ca + (cb - ca) * v1;
    const double st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
    const double phi = azimuth(wo) + (c + v2) * kTwoPi / P;
    const Vec3 wi(st * std::cos(phi), st * std::sin(phi), ct);
    return {wi, pdf_mix(m, wi, wo)};
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
  // Which view bins' tables, with which weights: linear in theta_o between
  // the two nearest bin centres, nearest phi_o bin; an empty table's weight
  // goes to the cosine lobe.
  Mix mix(const Vec3& wo) const {
    const int V = t_.view_bins, VP = t_.view_phi_bins;
    const double to = std::acos(std::min(1.0, std::max(0.0, wo.z())));
    const double x = std::min(std::max(to / kHalfPi * V - 0.5, 0.0), V - 1.0);
    const int a = std::min(static_cast<int>(x), V - 1), b = std::min(a + 1, V - 1);
    const double t = x - a;
    int vp = static_cast<int>(azimuth(wo) / kTwoPi * VP + 0.5);
    if (vp >= VP) vp = 0;
    Mix m;
    m.va = a * VP + vp, m.vb = b * VP + vp;
    const double rest = 1.0 - t_.cosine_fraction;
    m.w_a = t_.empty[m.va] ? 0.0 : rest * (1.0 - t);
    m.w_b = t_.empty[m.vb] ? 0.0 : rest * t;
    m.w_cos = 1.0 - m.w_a - m.w_b;
    return m;
  }
  double table_pdf(int v, const Vec3& wi, const Vec3& wo) const {
    const int T = t_.theta_bins, P = t_.phi_bins;
    const double ti = std::acos(std::min(1.0, wi.z()));
    const int r = std::min(static_cast<int>(ti / kHalfPi * T), T - 1);
    double pr = azimuth(wi) - azimuth(wo);
    if (pr < 0) pr += kTwoPi;
    const int c = std::min(static_cast<int>(pr / kTwoPi * P), P - 1);
    const float* rc = &t_.row_cdf[static_cast<size_t>(v) * (T + 1)];
    const float* cc = &t_.col_cdf[(static_cast<size_t>(v) * T + r) * (P + 1)];
    const double prob = (static_cast<double>(rc[r + 1]) - rc[r]) * (static_cast<double>(cc[c + 1]) - cc[c]);
    const double ca = std::cos(r * kHalfPi / T), cb = std::cos((r + 1) * kHalfPi / T);
    return prob / ((ca - cb) * kTwoPi / P);
  }
  double pdf_mix(const Mix& m, const Vec3& wi, const Vec3& wo) const {
    if (!above(wi)) return 0.0;
    double p = m.w_cos * cosine_pdf(wi);
    if (m.w_a > 0) p += m.w_a * table_pdf(m.va, wi, wo);
    if (m.w_b > 0) p += m.w_b * table_pdf(m.vb, wi, wo);
    return p;
  }

  SamplerTable t_;
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
  require(std::isfinite(cosine_fraction) && cosine_fraction > 0 && cosine_fraction < 1,
          "cosine_fraction", "a number in (0, 1)", cosine_fraction);
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
  t.cosine_fraction = o.cosine_fraction;
  const int V = t.view_bins * t.view_phi_bins, T = t.theta_bins, P = t.phi_bins, S = o.cell_samples;
  t.row_cdf.assign(static_cast<size_t>(V) * (T + 1), 0.0f);
  t.col_cdf.assign(static_cast<size_t>(V) * T * (P + 1), 0.0f);
  t.empty.assign(V, 1);
  std::vector<double> cell(static_cast<size_t>(T) * P), row(T);
  for (int vt = 0; vt < t.view_bins; ++vt) {
    for (int vp = 0; vp < t.view_phi_bins; ++vp) {
      const int v = vt * t.view_phi_bins + vp;
      const double to = (vt + 0.5) * kHalfPi / t.view_bins, po = vp * kTwoPi / t.view_phi_bins;
      const Vec3 wo(std::sin(to) * std::cos(po), std::sin(to) * std::sin(po), std::cos(to));
      double total = 0;
      for (int r = 0; r < T; ++r) {
        const double ca = std::cos(r * kHalfPi / T), cb = std::cos((r + 1) * kHalfPi / T);
        row[r] = 0;
        for (int c = 0; c < P; ++c) {
          double sum = 0;
          for (int i = 0; i < S; ++i) {
            const double ct = ca + (cb - ca) * (i + 0.5) / S;
            const double st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
            for (int j = 0; j < S; ++j) {
              const double phi = po + (c + (j + 0.5) / S) * kTwoPi / P;
              const Vec3 wi(st * std::cos(phi), st * std::sin(phi), ct);
              const double y = luminance(f.eval(wi, wo));
              if (std::isfinite(y) && y > 0) sum += y * ct;
            }
          }
          // Integral of f cos over the cell (solid angle (ca - cb) 2 pi / P).
          const double w = sum / (S * S) * (ca - cb) * kTwoPi / P;
          cell[static_cast<size_t>(r) * P + c] = w;
          row[r] += w;
        }
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

std::shared_ptr<const BrdfSampler> tabulated_sampler(SamplerTable t) {
  return std::make_shared<TabulatedSampler>(std::move(t));
}

const SamplerTable* sampler_table(const BrdfSampler& s) {
  const auto* t = dynamic_cast<const TabulatedSampler*>(&s);
  return t ? &t->table() : nullptr;
}

}  // namespace bf
