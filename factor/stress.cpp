// The stress matrix: case list, methods, condition estimate, CSV rows.
#include "factor/stress.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "brdfs/catalogue.h"
#include "factor/svd_baseline.h"

namespace bf {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// A BRDF given by a function (cases that no catalogue model expresses).
class FunctionBrdf final : public Brdf {
 public:
  FunctionBrdf(std::string name, std::function<Rgb(const Vec3&, const Vec3&)> f, bool iso = true)
      : name_(std::move(name)), f_(std::move(f)), iso_(iso) {}
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0 || wo.z() <= 0) return Rgb::Zero();
    return f_(wi, wo);
  }
  std::string name() const override { return name_; }
  std::string to_string() const override { return name_; }
  bool isotropic() const override { return iso_; }

 private:
  std::string name_;
  std::function<Rgb(const Vec3&, const Vec3&)> f_;
  bool iso_;
};

BrdfPtr function_brdf(std::string name, std::function<Rgb(const Vec3&, const Vec3&)> f,
                      bool iso = true) {
  return std::make_shared<FunctionBrdf>(std::move(name), std::move(f), iso);
}

Vec3 dir(double cos_theta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
  return Vec3(s * std::cos(phi), s * std::sin(phi), cos_theta);
}

// n random pairs with cos(theta) of both directions uniform in [c0, c1] and
// phi uniform in [0, 2 pi) (or 0 / pi only when in_plane).
SampleSet random_pairs(const Brdf& b, size_t n, double c0, double c1, uint64_t seed,
                       bool in_plane = false) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uc(c0, c1), up(0, 2 * M_PI);
  std::bernoulli_distribution side(0.5);
  SampleSet s;
  for (size_t k = 0; k < n; ++k) {
    const double pi = in_plane ? (side(rng) ? 0.0 : M_PI) : up(rng);
    const double po = in_plane ? (side(rng) ? 0.0 : M_PI) : up(rng);
    s.push(dir(uc(rng), pi), dir(uc(rng), po), Rgb::Zero());
  }
  evaluate_into(b, s);
  s.validate();
  return s;
}

StressExpectation finite() { return {}; }
StressExpectation bounded(double b) { return {StressExpectation::Kind::Bounded, b, {}}; }
StressExpectation error(std::string sub) { return {StressExpectation::Kind::Error, 0, std::move(sub)}; }
StressExpectation finite_or_error() { return {StressExpectation::Kind::FiniteOrError, 0, {}}; }

// Two wiwo projections with random orthonormal rows (Gram-Schmidt of Gaussian rows).
std::vector<TermSpec> random_terms(int res, uint64_t seed) {
  std::mt19937_64 rng(seed * 7919 + 13);
  std::normal_distribution<double> g;
  std::vector<TermSpec> t;
  for (int k = 0; k < 2; ++k) {
    Projection p;
    p.param = Parameterization::WiWo;
    p.res = res;
    Eigen::Vector4d a, b;
    for (int i = 0; i < 4; ++i) a[i] = g(rng);
    for (int i = 0; i < 4; ++i) b[i] = g(rng);
    a.normalize();
    b -= a.dot(b) * a;
    b.normalize();
    p.P.row(0) = a.transpose();
    p.P.row(1) = b.transpose();
    t.push_back({p, false, std::nullopt});
  }
  return t;
}

bool all_finite(const Rgb& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

}  // namespace

std::string StressExpectation::to_string() const {
  std::ostringstream o;
  switch (kind) {
    case Kind::Finite: return "finite";
    case Kind::Bounded: o << "rel_mse<=" << bound; return o.str();
    case Kind::Error: return "error~'" + substring + "'";
    case Kind::FiniteOrError: return "finite|error";
  }
  return "?";
}

StressExpectation StressExpectation::parse(const std::string& s) {
  if (s == "finite") return finite();
  if (s == "finite|error") return finite_or_error();
  if (s.rfind("rel_mse<=", 0) == 0) {
    char* end = nullptr;
    const std::string num = s.substr(9);
    const double b = std::strtod(num.c_str(), &end);
    if (num.empty() || *end != '\0' || !(b >= 0) || !std::isfinite(b))
      throw std::invalid_argument("expectation: expected rel_mse<=X with X a finite number >= 0, found '" + s + "'");
    return bounded(b);
  }
  if (s.size() >= 9 && s.rfind("error~'", 0) == 0 && s.back() == '\'')
    return error(s.substr(7, s.size() - 8));
  throw std::invalid_argument("expectation: expected one of finite, finite|error, rel_mse<=X, error~'TEXT', found '" +
                              s + "'");
}

void StressOptions::validate() const {
  if (res < 2 || res > 1024)
    throw std::invalid_argument("res: expected 2 <= res <= 1024, found " + std::to_string(res));
  if (samples < 50 || samples > 10000000)
    throw std::invalid_argument("samples: expected 50 <= samples <= 1e7, found " + std::to_string(samples));
  if (svd_res < 2 || svd_res > 256)
    throw std::invalid_argument("svd_res: expected 2 <= svd_res <= 256, found " + std::to_string(svd_res));
}

const StressExpectation& StressCase::expectation(const std::string& method) const {
  for (const auto& [m, e] : overrides)
    if (m == method) return e;
  return expect;
}

std::vector<std::string> stress_methods() { return {"mccool", "random2", "svd", "svd-log"}; }

// data table
std::vector<StressCase> stress_cases() {
  const Catalogue& cat = Catalogue::builtin();
  std::vector<StressCase> c;
  auto stratified = [&cat](const std::string& spec) {
    return [&cat, spec](const StressOptions& o) {
      BrdfPtr b = cat.make(spec, "stress");
      return StressInput{b, sample_stratified(*b, o.samples, o.seed), o.res};
    };
  };
  c.push_back({"blinn-phong-n1e4", "near-delta Blinn-Phong peak, exponent 1e4",
               stratified("blinn-phong:n=10000"), finite(), {{"mccool", bounded(0.1)}}});
  c.push_back({"ward-a0.005", "near-delta Ward peak, ax = ay = 0.005",
               stratified("ward:ax=0.005,ay=0.005"), finite(),
               {{"mccool", bounded(0.1)}, {"svd-log", bounded(0.1)}}});
  c.push_back({"beckmann-m0.01", "near-delta Cook-Torrance (Beckmann m = 0.01)",
               stratified("cook-torrance:m=0.01"), finite(), {{"mccool", bounded(0.1)}}});
  c.push_back({"grazing-only", "every sample with theta_i, theta_o in [80, 89.4] deg",
               [&cat](const StressOptions& o) {
                 BrdfPtr b = cat.make("cook-torrance:m=0.3", "stress");
                 return StressInput{b, random_pairs(*b, o.samples, 0.01, 0.17, o.seed), o.res};
               },
               finite(), {}});
  c.push_back({"half-zero", "BRDF exactly 0 wherever wi.x < 0 (zeros before the log)",
               [](const StressOptions& o) {
                 BrdfPtr b = function_brdf("half-zero", [](const Vec3& wi, const Vec3&) {
                   return wi.x() < 0 ? Rgb::Zero() : Rgb::Constant(0.3 / M_PI);
                 }, false);
                 return StressInput{b, sample_stratified(*b, o.samples, o.seed), o.res};
               },
               finite(), {}});
  c.push_back({"all-zero", "BRDF 0 everywhere: nothing to factor",
               [](const StressOptions& o) {
                 BrdfPtr b = function_brdf("zero", [](const Vec3&, const Vec3&) { return Rgb::Zero(); });
                 return StressInput{b, sample_stratified(*b, o.samples, o.seed), o.res};
               },
               error("mean"), {}});
  c.push_back({"range-1e12", "values spanning 12 orders of magnitude (1 down to 1e-12)",
               [](const StressOptions& o) {
                 BrdfPtr b = function_brdf("range-1e12", [](const Vec3& wi, const Vec3& wo) {
                   const Vec3 h = (wi + wo).normalized();
                   return Rgb::Constant(std::pow(10.0, -12.0 * (1 - h.z()) / (1 - std::sqrt(0.5))))
                       .min(1.0).max(1e-12);
                 });
                 return StressInput{b, sample_stratified(*b, o.samples, o.seed), o.res};
               },
               finite(), {}});
  c.push_back({"n-equals-h", "wi = wo for every sample, a quarter of them exactly at the normal (h = n)",
               [&cat](const StressOptions& o) {
                 BrdfPtr b = cat.make("blinn-phong:n=200", "stress");
                 SampleSet s = random_pairs(*b, o.samples, 0.2, 1.0, o.seed);
                 for (size_t k = 0; k < s.size(); ++k) {
                   s.wo[k] = s.wi[k];
                   if (k % 4 == 0) s.wi[k] = s.wo[k] = Vec3(0, 0, 1);
                 }
                 evaluate_into(*b, s);
                 s.validate();
                 return StressInput{b, s, o.res};
               },
               finite(), {}});
  c.push_back({"few-samples", "200 samples against a 64 x 64 texture (4 res, at most 64)",
               [&cat](const StressOptions& o) {
                 BrdfPtr b = cat.make("cook-torrance:m=0.2", "stress");
                 return StressInput{b, sample_stratified(*b, 200, o.seed), std::clamp(4 * o.res, 2, 64)};
               },
               finite(), {}});
  c.push_back({"duplicated", "50 distinct pairs, each repeated 20 times",
               [&cat](const StressOptions& o) {
                 BrdfPtr b = cat.make("cook-torrance:m=0.2", "stress");
                 SampleSet base = sample_stratified(*b, 50, o.seed), s;
                 for (int r = 0; r < 20; ++r)
                   for (size_t k = 0; k < base.size(); ++k) s.push(base.wi[k], base.wo[k], base.value[k]);
                 s.validate();
                 return StressInput{b, s, o.res};
               },
               finite(), {{"mccool", bounded(0.01)}}});
  c.push_back({"untouched-texels", "samples only within 18 deg of the normal: most texels see no sample",
               [&cat](const StressOptions& o) {
                 BrdfPtr b = cat.make("cook-torrance:m=0.2", "stress");
                 return StressInput{b, random_pairs(*b, o.samples, 0.95, 1.0, o.seed), o.res};
               },
               finite(), {}});
  c.push_back({"thin-image", "samples in the plane of incidence: p(wi), p(wo) project onto a segment",
               [&cat](const StressOptions& o) {
                 BrdfPtr b = cat.make("cook-torrance:m=0.2", "stress");
                 return StressInput{b, random_pairs(*b, o.samples, 0.05, 1.0, o.seed, true), o.res};
               },
               finite(), {}});
  c.push_back({"ward-aniso-rot30", "anisotropic Ward (ax 0.05, ay 0.3) rotated 30 deg about the normal",
               [&cat](const StressOptions& o) {
                 BrdfPtr w = cat.make("ward:ax=0.05,ay=0.3", "stress");
                 const Eigen::Matrix3d R = Eigen::AngleAxisd(-M_PI / 6, Vec3::UnitZ()).toRotationMatrix();
                 BrdfPtr b = function_brdf("ward-rot30", [w, R](const Vec3& wi, const Vec3& wo) {
                   return w->eval(R * wi, R * wo);
                 }, false);
                 return StressInput{b, sample_stratified(*b, o.samples, o.seed), o.res};
               },
               finite(), {{"mccool", bounded(0.5)}}});
  c.push_back({"denormal", "every value a denormal double (about 1e-310)",
               [](const StressOptions& o) {
                 BrdfPtr b = function_brdf("denormal", [](const Vec3& wi, const Vec3& wo) {
                   return Rgb::Constant(1e-310 * (1 + wi.z() * wo.z()));
                 });
                 return StressInput{b, sample_stratified(*b, o.samples, o.seed), o.res};
               },
               finite(), {{"svd", error("denormal")}}});
  c.push_back({"huge-1e300", "every value about 1e300 (sums overflow double)",
               [](const StressOptions& o) {
                 BrdfPtr b = function_brdf("huge", [](const Vec3& wi, const Vec3& wo) {
                   return Rgb::Constant(1e300 * (1 + wi.z() * wo.z()));
                 });
                 return StressInput{b, sample_stratified(*b, o.samples, o.seed), o.res};
               },
               finite_or_error(), {}});
  c.push_back({"nan-inf-samples", "a third of the sample values NaN, Inf or negative (masked)",
               [&cat](const StressOptions& o) {
                 BrdfPtr b = cat.make("cook-torrance:m=0.2", "stress");
                 SampleSet s = sample_stratified(*b, o.samples, o.seed);
                 for (size_t k = 0; k < s.size(); k += 3)
                   s.value[k] = Rgb(k % 2 ? std::numeric_limits<double>::quiet_NaN() : -1.0,
                                    std::numeric_limits<double>::infinity(), 0.1);
                 s.validate();
                 return StressInput{b, s, o.res};
               },
               finite(), {}});
  return c;
}

double normal_matrix_condition(const FitData& d, const std::vector<TermSpec>& joint,
                               const FitOptions& opt, size_t max_unknowns, size_t* unknowns) {
  // The fit's own normal matrix (factor/homomorphic_fit.h), without its ridge.
  const Eigen::MatrixXd A = joint_normal_matrix(d, joint, opt, max_unknowns, unknowns);
  if (A.size() == 0) return kNaN;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(A, Eigen::EigenvaluesOnly);
  if (es.info() != Eigen::Success) return kNaN;
  const double lo = es.eigenvalues().minCoeff(), hi = es.eigenvalues().maxCoeff();
  if (!(lo > 0)) return std::numeric_limits<double>::infinity();
  return hi / lo;
}

StressResult run_stress(const StressCase& c, const StressInput& in, const std::string& method,
                        const StressOptions& opt) {
  const std::vector<std::string> methods = stress_methods();
  if (std::find(methods.begin(), methods.end(), method) == methods.end())
    throw std::invalid_argument("stress: unknown method '" + method + "'");
  StressResult r;
  r.case_name = c.name;
  r.method = method;
  r.rel_mse = r.cos_rmse = r.condition = kNaN;
  const StressExpectation& e = c.expectation(method);
  r.expectation = e.to_string();
  const auto t0 = std::chrono::steady_clock::now();
  try {
    FitOptions fo;
    FactorizationPtr f;
    if (method == "mccool" || method == "random2") {
      FitData d(in.samples, fo.eps);
      const std::vector<TermSpec> terms =
          method == "mccool" ? mccool_terms(in.res) : random_terms(in.res, opt.seed);
      r.condition = normal_matrix_condition(d, terms, fo, opt.cond_max_unknowns, &r.unknowns);
      f = fit_homomorphic(d, terms, fo, method);
    } else {
      SvdOptions so;
      so.res = opt.svd_res;
      so.rank = 2;
      so.log = method == "svd-log";
      f = fit_svd(*in.brdf, so);
    }
    const LogTransform t = LogTransform::of(in.samples, fo.eps);
    const Metrics m = evaluate_metrics(*f, in.samples, t);
    r.finite = true;
    for (size_t k = 0; k < in.samples.size() && r.finite; ++k)
      if (in.samples.valid[k]) r.finite = all_finite(f->eval(in.samples.wi[k], in.samples.wo[k]));
    r.rel_mse = m.rel_mse;
    r.cos_rmse = m.cos_rmse;
    // evaluate_metrics charges a non-finite approximation 1e300. Log-space errors
    // of finite values stay below ~1500^2, so rel_mse near 1e300 means one;
    // cos_rmse may legitimately approach the cap for a BRDF of about 1e300.
    r.finite = r.finite && std::isfinite(m.rel_mse) && std::isfinite(m.cos_rmse) && m.rel_mse < 1e299;
  } catch (const std::exception& ex) {
    r.threw = true;
    r.message = ex.what();
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  switch (e.kind) {
    case StressExpectation::Kind::Finite: r.pass = !r.threw && r.finite; break;
    case StressExpectation::Kind::Bounded: r.pass = !r.threw && r.finite && r.rel_mse <= e.bound; break;
    case StressExpectation::Kind::Error:
      r.pass = r.threw && r.message.find(e.substring) != std::string::npos;
      break;
    case StressExpectation::Kind::FiniteOrError:
      r.pass = r.threw ? !r.message.empty() : r.finite;
      break;
  }
  return r;
}

std::string stress_csv_header() {
  return "case,method,finite,rel_mse,cos_rmse,condition,unknowns,seconds,expectation,pass,message";
}

std::string stress_csv_row(const StressResult& r) {
  auto quote = [](const std::string& s) {
    std::string q = "\"";
    for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
  };
  auto num = [](double v) {
    if (std::isnan(v)) return std::string();
    std::ostringstream o;
    o.precision(6);
    o << v;
    return o.str();
  };
  std::ostringstream o;
  o << r.case_name << ',' << r.method << ',' << (r.threw ? "error" : r.finite ? "yes" : "no") << ','
    << num(r.rel_mse) << ',' << num(r.cos_rmse) << ',' << num(r.condition) << ',' << r.unknowns << ','
    << num(r.seconds) << ',' << quote(r.expectation) << ',' << (r.pass ? "pass" : "FAIL") << ','
    << quote(r.message);
  return o.str();
}

}  // namespace bf
