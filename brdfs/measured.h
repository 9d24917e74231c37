// Measured BRDFs given as scattered samples: the Cornell ASTM E1392 (.astm) and
// pbrt-v2 (.brdf) spectral readers, MeasuredBrdf (isotropic scattered-data
// interpolation of a sample list) and access to the raw measured samples.
//
// Catalogue entries registered by register_measured_loaders (measured.cpp):
//   files:  X.astm[:band=550,k=8]  X.brdf[:band=..,k=..]  X.csv[:k=..]
//           X.binary[:lookup=nearest|linear]  (MERL, see merl.h)
//   models: krylon-blue, garnet-red, cayman, acryl-blue (data/cornell/<name>.astm)
//           and mystique (data/cornell/mystique.brdf), each with the options
//           band and k of the file loaders. They are models (not presets)
//           because presets map to a model plus parameters, and these map to a
//           data file; each make() reads the file anew (no hidden cache).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/sampleset.h"
#include "brdfs/spectral.h"

namespace bf {

// A spectral measurement file as read, before any colour conversion.
struct SpectralMeasurements {
  std::string path;
  std::string sample_name;  // ASTM SAMPLE_NAME, or the .brdf file's stem
  // Record k: (theta_i, phi_i, theta_s, phi_s) in radians; theta from the
  // normal, phi from +x towards +y, both directions pointing away from the
  // surface (i = towards the light, s = towards the viewer). The mirror
  // direction of (theta_i, 0) is (theta_i, pi).
  std::vector<std::array<double, 4>> angles;
  // values[k * kSpectralBands + b]: BRDF of record k at 400 + 10 b nm, in 1/sr.
  // Finite; negative entries mark invalid measurements (masked downstream).
  std::vector<double> values;
  size_t size() const { return angles.size(); }
};

// Upper bound on the records of one scattered file (absurd counts are errors).
constexpr size_t kMaxMeasuredRecords = 10'000'000;

// Reads a Cornell ASTM E1392 file: "KEY value" header lines up to
// "VARS theta_i,phi_i,theta_s,phi_s,400nm,...,700nm", then one comma-separated
// row of 35 numbers per non-empty line. Throws std::invalid_argument naming
// path:line, what was expected and what was found, for: no VARS line, VARS
// columns other than those 35, a header line that is not "KEY value", a
// NUM_POINTS that is not an integer in 1..kMaxMeasuredRecords or differs
// from the number of rows, a row without 35 cells, a cell that is not a
// number, NaN/Inf, theta outside [0, pi/2] or phi outside [-2 pi, 2 pi]
// (angles in degrees are caught here), no data rows, lines over 64 KiB.
SpectralMeasurements read_astm(const std::string& path);

// Reads a pbrt-v2 "irregular isotropic" .brdf file: '#' comments to the end
// of the line, then a whitespace-separated number stream: nWavelengths (must
// be 31), the wavelengths (400, 410, ..., 700), then records of
// theta_i phi_i theta_s phi_s and 31 values. Line breaks are not significant
// (CRLF is fine). Throws std::invalid_argument naming path:line, expected and
// found, for: a token that is not a number, a wavelength count other than 31,
// a wavelength out of place, NaN/Inf, an incomplete last record (truncated
// file), the angle ranges of read_astm, no records, more than
// kMaxMeasuredRecords records.
SpectralMeasurements read_pbrt_brdf(const std::string& path);

// Converts measurements to a SampleSet: wi from (theta_i, phi_i), wo from
// (theta_s, phi_s); value = RGB by spectral.h (band_nm == 0) or the single band
// band_nm (400, 410, ..., 700) in all three channels. A record with a
// negative value in a band that contributes is masked (its value set to -1).
// Colours with a channel below gamut_floor x their luminance (out of gamut,
// or at its edge) are desaturated at constant luminance until every channel
// is gamut_floor x Y (spectral.h, step 4; kGamutFloor by default); their
// count goes to *desaturated and into the description.
// Throws std::invalid_argument for a band_nm that is not a band.
SampleSet spectral_to_samples(const SpectralMeasurements& m, int band_nm,
                              size_t* desaturated = nullptr, double gamut_floor = kGamutFloor);

struct MeasuredOptions {
  int neighbours = 8;  // k of the interpolation below, 1..64 (loader option `k`)
  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
};

// Marschner's isotropic embedding of a direction pair, the space MeasuredBrdf
// interpolates in: (sin th_i sin th_o, cos th_i cos th_o, |dphi| / pi), dphi =
// phi_o - phi_i wrapped to [-pi, pi]. Each coordinate is in [0, 1]. It is
// symmetric under wi <-> wo (reciprocity) and dphi -> -dphi (bilateral
// symmetry), and one-to-one on isotropic pairs up to those symmetries.
Vec3 marschner_point(const Vec3& wi, const Vec3& wo);

// An isotropic BRDF given by scattered samples.
//
// eval: Franke-Nielson modified Shepard interpolation in marschner_point
// space: the k nearest valid samples (kd-tree), distances d_j, R = distance to
// the (k+1)-th nearest (or twice the k-th when there are only k samples),
// weights ((R - d_j) / (R d_j))^2, value = sum w_j f_j / sum w_j. It
// reproduces the samples exactly (a query within 1e-12 of a sample returns
// it), is continuous, stays within the range of the neighbours (so it is
// non-negative and finite), and is reciprocal, isotropic and bilateral by
// construction of the space; it claims (isotropic() etc.) only what its
// samples declare. Outside the measured angles (e.g. theta > 80 degrees for the
// Cornell data) it extends the nearest measurements; below the horizon it is 0.
class MeasuredBrdf final : public Brdf {
 public:
  // name: catalogue name ("astm", "cayman", ...). samples: the measured list;
  // masked samples stay in samples() but are never interpolated. Throws
  // std::invalid_argument when no sample is valid or the options are invalid.
  MeasuredBrdf(std::string name, SampleSet samples, const MeasuredOptions& options);

  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  std::string name() const override { return name_; }
  std::string to_string() const override;
  // The symmetries the samples declare (SampleSet::symmetries), not those the
  // interpolation has by construction: the interpolant equals the measured
  // BRDF over the whole domain only when all three are declared.
  bool reciprocal() const override;
  bool isotropic() const override;
  bool bilateral() const override;
  // True when the samples declare isotropic, reciprocal and bilateral (what
  // the interpolation in Marschner's space assumes).
  bool whole_domain(std::string* why = nullptr) const override;

  // The raw measured samples (with validity), for fits that use the measured
  // list directly (thesis 1.3.2).
  const SampleSet& samples() const;
  const MeasuredOptions& options() const { return options_; }

 private:
  struct Table;
  std::string name_;
  MeasuredOptions options_;
  std::shared_ptr<const Table> table_;
};

// The samples a measured BRDF is made of: MeasuredBrdf -> its raw list,
// MerlBrdf -> one sample per table cell (missing cells masked), weighted by
// each cell's measure when measure_weights (MerlBrdf::samples). Throws
// std::invalid_argument for any other BRDF, naming it, and for
// measure_weights on scattered samples (their measure is not known).
SampleSet measured_samples(const Brdf& brdf, bool measure_weights = false);
// Whether measured_samples can weight this BRDF's samples by measure (a MERL table).
bool has_cell_measure(const Brdf& brdf);

// The measured BRDF made of `train` only (the samples a fit may see, e.g. the
// training part of a held-out split): MeasuredBrdf -> the interpolant of
// `train` with the same name and options (train's declared symmetries);
// MerlBrdf -> the same table with every cell not in `train` missing, read with
// trilinear lookup (missing corners dropped and the rest renormalized, so a
// removed cell is filled from its neighbours). nullptr for any other BRDF.
// Throws std::invalid_argument when train has no valid sample.
BrdfPtr measured_from_training(const Brdf& brdf, const SampleSet& train);

}  // namespace bf
