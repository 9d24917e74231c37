// Fits of the catalogue's analytic BRDF models (Blinn-Phong, Cook-Torrance,
// Ward, Ashikhmin-Shirley, Lafortune with 1-3 lobes) to any sample set, with
// Ceres, so that analytic models stand in the same comparison tables as the
// factorizations (method "model-fit", storage = number of fitted parameters).
//
// Models and fitted parameters (isotropic forms; fixed options come from the
// model spec, e.g. "cook-torrance:form=ngan"; formulas: brdfs/models.h):
//   blinn-phong        kd (RGB), ks (RGB), n            fixed: normalization
//   cook-torrance      kd, ks (RGB), m, f0 (Schlick)    fixed: form (fresnel must be schlick)
//   ward               kd, ks (RGB), a = ax = ay        fixed: variant
//                      (anisotropic: ax, ay)
//   ashikhmin-shirley  rd, ks (RGB), rs, n = nu = nv    fixed: diffuse
//                      (anisotropic: nu, nv)
//   lafortune          rho_d (RGB); per lobe k < lobes: ks<k> (RGB), the lobe
//                      direction angle alpha (cxy<k> = cos alpha / m,
//                      cz<k> = sin alpha / m, m = max(|cos|, |sin|): the C
//                      scale is redundant with ks), n<k>;
//                      normalization=none: alpha and n per channel (pbrt-v1's
//                      form), ngan: one alpha and n per lobe (Ngan et al.)
// Parameters stay in range by reparameterization: exp of a free variable for
// positive values (kd, ks, rd, rho_d, m, a, n; the variable clamped to
// [-40, 40], i.e. 4e-18 .. 2.4e17, so degenerate lobes cannot overflow), the
// logistic function for values in (0, 1) (f0, rs), alpha free.
//
// Metrics (per valid sample k with weight w_k, W = sum of w_k, channel c;
// Abar = mean over channels of the per-channel sample means A_c):
//  - "cosine": Ngan, Matusik and Durand 2005's fitting error, the weighted L2
//    distance of the cosine-weighted BRDFs:
//      r_kc = sqrt(w_k / 3W) (f_model - f) cos(theta_i) / Abar,
//    so 2 * cost = cos_rmse^2 / Abar^2 (docs/design.md §4).
//    cube_root = true compresses the dynamic range first:
//      r_kc = sqrt(w_k / 3W) (cbrt(f_model cos theta_i) - cbrt(f cos theta_i)) / cbrt(Abar).
//    Which of the two Ngan et al. used for their published tables is not
//    verified here (their paper is not in papers/); "cosine" without the cube
//    root is the default and the metric our cos_rmse column reports.
//  - "log": the homomorphic transform of docs/design.md §2,
//      r_kc = sqrt(w_k / 3W) (log((f_model + eps A_c) / A_c) - g_kc),
//      g_kc = log((f + eps A_c) / A_c),
//    so 2 * cost = rel_mse, the metric the factorizations minimize.
//
// Search: `starts` Levenberg-Marquardt runs (dense normal Cholesky; the
// residuals of 256 samples form one block, auto-differentiated with
// ceres::DynamicAutoDiffCostFunction). Start 0 uses documented default
// values of the nonlinear parameters (model_fit.cpp), starts 1.. draw them
// from seeded ranges (log-uniform for positive values); in every start the
// linear parameters (kd, ks, rd, rho_d, ks<k>) are then set by a weighted
// linear least-squares fit per channel (cos^2 theta_i weights for "cosine",
// 1/(f + 0.01 A)^2 for "log"), clamped at 1e-6. The lowest final cost wins;
// for lafortune with normalization=none every parameter acts on one channel,
// the channels are independent problems, and each channel takes the
// parameters of its own best start.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "brdfs/sampleset.h"
#include "factor/factorization.h"

namespace bf {

struct ModelFitOptions {
  // "model" or "model:k=v,...": a model name above plus fixed options only
  // (normalization, form, fresnel=schlick, variant, diffuse); fitted keys are
  // refused.
  std::string model = "cook-torrance";
  int lobes = 1;                  // lafortune only: 1..3
  // ward, ashikhmin-shirley only: fit the two roughnesses (ax, ay) or
  // exponents (nu, nv) separately, along the tangent frame's x and y axes
  // (the catalogue models' frame); false fits one shared value.
  bool anisotropic = false;
  std::string metric = "cosine";  // "cosine" | "log" (see above)
  bool cube_root = false;         // "cosine" only: compare cube roots (see above)
  double eps = 1e-5;              // "log": transform epsilon, 0 < eps <= 1
  int starts = 8;                 // multi-start count, 1..1000
  uint64_t seed = 1;              // random starts 1.. are deterministic for a seed
  int max_iterations = 100;       // Levenberg-Marquardt iterations per start, >= 1
  int threads = 0;                // Ceres threads; 0 = all hardware threads
  // Throws OptionError (solvers/option_error.h) naming the field, its value
  // and the rule; unknown models and fixed options are reported when fitting.
  void validate() const;
};

struct ModelFitResult {
  std::string model;  // catalogue model name, e.g. "cook-torrance"
  // Catalogue spec of the fitted model with every fitted and fixed key, e.g.
  // "ward:kd=0.03/0.06/0.09,ks=0.04/0.03/0.02,ax=0.29,ay=0.29,variant=ward";
  // Catalogue::builtin().make(spec) rebuilds `brdf`.
  std::string spec;
  BrdfPtr brdf;
  // Fitted parameters in natural units, in fit order: "kd.r", "kd.g", "kd.b",
  // ..., "m", "alpha0" (radians), "n0.r", ...
  std::vector<std::pair<std::string, double>> parameters;
  std::string metric;       // as fitted
  bool cube_root = false;
  bool anisotropic = false;  // as fitted
  double cost = 0;          // Ceres cost of the best start (half the sum of squared residuals)
  size_t storage_floats = 0;  // number of fitted parameters
  // Index of the winning start; -1 when the channels of a channel-separable
  // model (lafortune, normalization=none) come from different starts
  // (channel_starts says which).
  int best_start = 0;
  std::array<int, 3> channel_starts{-1, -1, -1};  // separable models: best start per channel
  std::vector<double> start_costs;  // final cost of every start
  int iterations = 0;       // Levenberg-Marquardt iterations, all starts
  double seconds = 0;       // wall time of fit_model()
  // Value of a fitted parameter by name; throws std::out_of_range naming it.
  double parameter(const std::string& name) const;
};

// Checks opt (validate()) and its model spec (known model, fixed options, lobes
// and anisotropic allowed for it) without fitting: the experiment config calls
// it so that a bad model is reported before any run. Throws
// std::invalid_argument as fit_model() does. Returns the number of fitted
// parameters (the storage of the fit).
size_t check_model_fit(const ModelFitOptions& opt);

// Reads back a model fit written by write_model_fit: the catalogue BRDF of its
// `spec`. Throws std::invalid_argument naming the file and field.
BrdfPtr load_model_fit(const std::string& json_path);
// Model-fit files are JSON with "format" = this value (format_version 1):
// describe() of the fit plus format and format_version; `spec` is what
// load_model_fit (and `--brdf FILE.json`) rebuild.
inline constexpr const char* kModelFitFormat = "brdf-factor-model-fit";
// Writes the fit as such a file (atomically: a temporary renamed into place).
void write_model_fit(const ModelFitResult& r, const std::string& path);

// Fits opt.model to the valid samples of s. Throws std::invalid_argument for
// invalid options, an unknown model or fixed option, fresnel=dielectric, or a
// sample set without valid samples or with an all-zero channel;
// std::runtime_error if no start produced a finite fit.
ModelFitResult fit_model(const SampleSet& s, const ModelFitOptions& opt);

// A model fit as a Factorization: method "model-fit", storage_floats = number
// of fitted parameters, evaluation by the fitted catalogue model, describe() =
// model, spec, parameters, metric and cost.
class ModelFitFactorization final : public Factorization {
 public:
  explicit ModelFitFactorization(ModelFitResult r);
  Rgb eval(const Vec3& wi, const Vec3& wo) const override { return r_.brdf->eval(wi, wo); }
  std::string name() const override { return "model-fit"; }
  std::string to_string() const override { return "model-fit(" + r_.spec + ")"; }
  bool reciprocal() const override { return r_.brdf->reciprocal(); }
  bool isotropic() const override { return r_.brdf->isotropic(); }
  std::string method() const override { return "model-fit"; }
  size_t storage_floats() const override { return r_.storage_floats; }
  nlohmann::json describe() const override;
  // Outputs (factor/factorization.h), defined in factor/export.cpp.
  ExportedFiles write_export_files(const std::string& dir, const std::string& stem,
                                   const std::string& origin) const override;
  std::string glsl(const std::string& stem, const std::string& origin) const override;
  std::optional<ShaderView> viewer_data() const override;
  const ModelFitResult& result() const { return r_; }

 private:
  ModelFitResult r_;
};

}  // namespace bf
