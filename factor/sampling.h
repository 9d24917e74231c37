// Importance sampling of any BRDF: draw wi for a given wo with a known pdf, so
// that a path tracer can use a factorization (or a measured or analytic BRDF)
// the way it uses an analytic model. Method, pdf formula, storage and options:
// docs/design.md, "Importance sampling".
//
// Frame: the local shading frame of brdfs/brdf.h (z = normal); wi and wo unit,
// pointing away from the surface. pdf is per unit solid angle of wi.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "brdfs/brdf.h"

namespace bf {

struct DirectionSample {
  Vec3 wi = Vec3::Zero();
  double pdf = 0;  // per solid angle; pdf 0 = no sample
};

class BrdfSampler {
 public:
  virtual ~BrdfSampler() = default;
  // wi for the outgoing wo (local frame, z = normal, both unit), from u1, u2 in [0,1).
  virtual DirectionSample sample(const Vec3& wo, double u1, double u2) const = 0;
  // Exactly the density sample() draws; positive for every wi above the
  // horizon when wo is above it, 0 below.
  virtual double pdf(const Vec3& wi, const Vec3& wo) const = 0;
  // Floats a renderer must hold to sample (0 for the cosine sampler).
  virtual size_t storage_floats() const = 0;
  virtual std::string method() const = 0;  // "tabulated", "cosine", "model"
};

struct SamplerOptions {
  // Bins of the view direction's polar angle theta_o over [0, pi/2), uniform
  // in theta_o; the table between two bin centres is a mixture of both
  // (weights linear in cos theta_o). 1..256.
  int view_bins = 16;
  // Cells of wi: theta_bins uniform in theta_i over [0, pi/2] times
  // phi_bins uniform in the azimuth of wi relative to that of wo over
  // [0, 2 pi). 2..1024 each.
  int theta_bins = 32;
  int phi_bins = 64;
  // Bins of the view azimuth phi_o over [0, 2 pi) (nearest bin). 0 = 1 for a
  // BRDF that says it is isotropic (Brdf::isotropic()), else 16. 0..256.
  // 1 for a BRDF that does not say it is isotropic (a factorization of an
  // isotropic BRDF): the table is the mean of f cos over 8 view azimuths.
  int view_phi_bins = 0;
  // Probability of drawing wi from the cosine lobe cos(theta_i) / pi instead
  // of the table: keeps the pdf positive over the whole hemisphere. (0, 1);
  // used rounded to float32 (as the GLSL export holds it).
  double cosine_fraction = 0.1;
  // f cos theta_i is integrated over each cell by a cell_samples^2 midpoint
  // rule (uniform in cos theta_i and phi_i). 1..16.
  int cell_samples = 2;
  // "auto": the analytic model's own sampler where one exists (Cook-Torrance:
  // its Beckmann distribution of normals), else the table; "tabulated": the
  // table for every BRDF.
  std::string method = "auto";
  // Throws OptionError naming the field, its value and the rule.
  void validate() const;
};

// The sampler of f (any Brdf: analytic, measured, or a Factorization).
// Throws on invalid options.
std::shared_ptr<const BrdfSampler> make_sampler(const Brdf& f, const SamplerOptions& o = {});
// Cosine-weighted hemisphere sampling: pdf = cos(theta_i) / pi.
std::shared_ptr<const BrdfSampler> cosine_sampler();

// The data of a tabulated sampler, for export (factor/sampling_export.h) and
// GLSL. View bin v = vt * view_phi_bins + vp (vt: theta_o bin, vp: phi_o bin);
// row_cdf[v * (theta_bins + 1) + r]: marginal CDF over theta rows (0 first,
// 1 last; all 0 for an empty view bin: f cos <= 0 everywhere);
// col_cdf[(v * theta_bins + r) * (phi_bins + 1) + c]: CDF over phi cells of
// row r (0 first, 1 last).
struct SamplerTable {
  int view_bins = 0, view_phi_bins = 0, theta_bins = 0, phi_bins = 0;
  double cosine_fraction = 0;
  std::vector<float> row_cdf, col_cdf;
  std::vector<unsigned char> empty;  // per view bin: 1 = no table (cosine only)
};
// The values the tabulated sampler compares directions with, rounded to
// float32 (the GLSL export holds the same values as constants, so CPU and GPU
// bin a direction alike): view_cos[k] = cos of the centre of theta_o bin k,
// (k + 1/2) pi / (2 view_bins), decreasing; row_omc[r] = 1 - cos of the
// edge r pi / (2 theta_bins) of the theta_i rows (theta_bins + 1 values, 0
// first, 1 last; 1 - cos rather than cos keeps the rows near the normal
// precise in float32). Row r holds row_omc[r] <= 1 - cos theta_i < row_omc[r + 1].
struct SamplerGeometry {
  std::vector<double> view_cos, row_omc;
};
SamplerGeometry sampler_geometry(const SamplerTable& t);
// The table of a tabulated sampler; nullptr for other methods.
const SamplerTable* sampler_table(const BrdfSampler& s);

}  // namespace bf
