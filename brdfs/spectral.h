// Spectral -> linear RGB conversion for measured spectral BRDFs (31 bands,
// 400..700 nm in 10 nm steps, the band set of the Cornell data).
//
// How a spectrum becomes RGB (the one documented choice, used everywhere):
//  1. The BRDF spectrum f(lambda) is lit by an equal-energy illuminant E and
//     integrated against the CIE 1931 2-degree colour-matching functions over
//     the 31 bands (rectangle rule, 10 nm per band):
//        X = sum_k f_k xbar_k,  Y = sum_k f_k ybar_k,  Z = sum_k f_k zbar_k.
//  2. XYZ -> linear sRGB with the matrix derived from the sRGB primaries and
//     the D65 white point (IEC 61966-2-1 chromaticities).
//  3. White balance: each RGB channel is divided by the RGB that a spectrally
//     flat BRDF of value 1 produces under steps 1-2. So a flat spectrum of
//     value v maps to exactly (v, v, v) (a grey of the same magnitude), and
//     the conversion is a 3 x 31 matrix whose rows each sum to 1. (This is a
//     von Kries-type diagonal adaptation from E to the sRGB white, done in the
//     sRGB primaries; it keeps BRDF magnitudes in 1/sr.)
//  4. Gamut: saturated spectra fall outside the sRGB gamut and give a negative
//     channel (the Cornell "cayman" paint is a saturated blue-green: most of
//     its samples have red < 0, down to -0.85 times the largest channel).
//     spectrum_to_rgb() returns that as is; desaturate_into_gamut() (used by
//     the measured loaders) mixes the colour with the grey of the same
//     luminance Y until the smallest channel is floor x Y (kGamutFloor for
//     the loaders; 0 reaches the gamut's edge). That keeps Y (and
//     the hue, roughly) and gives up saturation, unlike per-channel clipping,
//     which would add red light and shift both.
#pragma once

#include <Eigen/Core>
#include <array>

#include "brdfs/brdf.h"

namespace bf {

constexpr int kSpectralBands = 31;  // 400, 410, ..., 700 nm
constexpr double kSpectralFirstNm = 400.0;
constexpr double kSpectralStepNm = 10.0;

// Wavelength of band k (0 <= k < kSpectralBands), in nm.
double spectral_band_nm(int k);
// Index of the band at `nm` (must be one of 400, 410, ..., 700 exactly, within
// 1e-9). Throws std::invalid_argument naming the accepted values otherwise.
// `what` prefixes the message ("cayman.astm: band").
int spectral_band_index(double nm, const std::string& what);

// CIE 1931 2-degree colour-matching functions at band k: (xbar, ybar, zbar).
Eigen::Vector3d cie1931_cmf(int k);

// Linear sRGB from CIE XYZ (D65 white), derived from the primaries.
Eigen::Matrix3d xyz_to_linear_srgb();

// The 3 x 31 matrix of steps 1-3 above: rgb = M * spectrum. Rows sum to 1.
Eigen::Matrix<double, 3, kSpectralBands> spectrum_to_rgb_matrix();

// rgb of one spectrum: `spectrum` holds kSpectralBands values (400..700 nm),
// in any unit (the result has the same unit). May be slightly negative for
// out-of-gamut spectra.
Rgb spectrum_to_rgb(const Eigen::Matrix<double, 3, kSpectralBands>& m, const double* spectrum);

// Luminance weights of the white-balanced RGB above: Y = w . rgb is CIE Y
// normalized so that a flat spectrum of value v has Y = v (w sums to 1).
Eigen::Vector3d rgb_luminance_weights();

// The floor of step 4 the measured loaders use: every channel at least this
// fraction of the sample's luminance Y (docs/design.md §8.2 "zero channels").
// A gamut mapping to exactly 0 leaves channels the log metrics read as
// ln(eps), far below their neighbours; 1% of Y is below every Cornell
// paint's in-gamut channels but for the mapped ones (garnet-red: 5% of its
// in-gamut samples have their smallest channel under 7% of Y).
inline constexpr double kGamutFloor = 0.01;

// Step 4: if a channel of rgb is below floor x Y (Y = w . rgb; floor in
// [0, 1)), replaces rgb by Y + t (rgb - Y) with the largest t in [0, 1) that
// makes every channel >= floor x Y; rgb with Y <= 0 becomes 0. Y is kept.
// Returns whether rgb changed.
bool desaturate_into_gamut(Rgb& rgb, const Eigen::Vector3d& luminance_weights, double floor = 0.0);

}  // namespace bf
