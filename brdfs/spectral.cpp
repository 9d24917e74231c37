// Spectral -> linear sRGB conversion (see spectral.h for the treatment of the spectrum).
#include "brdfs/spectral.h"

#include <Eigen/LU>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace bf {

namespace {

// CIE 1931 2-degree standard colorimetric observer, xbar / ybar / zbar at
// 400, 410, ..., 700 nm: the 10 nm rows of the CIE's published 5 nm table
// (CIE 15:2004 "Colorimetry", table T.4; the same values appear in Wyszecki &
// Stiles, "Color Science", 2nd ed., table I(3.3.1)). Typed in for this file.
constexpr double kCmf[kSpectralBands][3] = {
    {0.014310, 0.000396, 0.067850},  // 400
    {0.043510, 0.001210, 0.207400},  // 410
    {0.134380, 0.004000, 0.645600},  // 420
    {0.283900, 0.011600, 1.385600},  // 430
    {0.348280, 0.023000, 1.747060},  // 440
    {0.336200, 0.038000, 1.772110},  // 450
    {0.290800, 0.060000, 1.669200},  // 460
    {0.195360, 0.090980, 1.287640},  // 470
    {0.095640, 0.139020, 0.812950},  // 480
    {0.032010, 0.208020, 0.465180},  // 490
    {0.004900, 0.323000, 0.272000},  // 500
    {0.009300, 0.503000, 0.158200},  // 510
    {0.063270, 0.710000, 0.078250},  // 520
    {0.165500, 0.862000, 0.042160},  // 530
    {0.290400, 0.954000, 0.020300},  // 540
    {0.433450, 0.994950, 0.008750},  // 550
    {0.594500, 0.995000, 0.003900},  // 560
    {0.762100, 0.952000, 0.002100},  // 570
    {0.916300, 0.870000, 0.001650},  // 580
    {1.026300, 0.757000, 0.001100},  // 590
    {1.062200, 0.631000, 0.000800},  // 600
    {1.002600, 0.503000, 0.000340},  // 610
    {0.854450, 0.381000, 0.000190},  // 620
    {0.642400, 0.265000, 0.000050},  // 630
    {0.447900, 0.175000, 0.000020},  // 640
    {0.283500, 0.107000, 0.000000},  // 650
    {0.164900, 0.061000, 0.000000},  // 660
    {0.087400, 0.032000, 0.000000},  // 670
    {0.046770, 0.017000, 0.000000},  // 680
    {0.022700, 0.008210, 0.000000},  // 690
    {0.011359, 0.004102, 0.000000},  // 700
};

// XYZ of a chromaticity (x, y) with Y = 1.
Eigen::Vector3d xyz_of_chromaticity(double x, double y) {
  return Eigen::Vector3d(x / y, 1.0, (1.0 - x - y) / y);
}

}  // namespace

double spectral_band_nm(int k) {
  if (k < 0 || k >= kSpectralBands)
    throw std::out_of_range("spectral band index: expected 0..30, found " + std::to_string(k));
  return kSpectralFirstNm + kSpectralStepNm * k;
}

int spectral_band_index(double nm, const std::string& what) {
  const double k = (nm - kSpectralFirstNm) / kSpectralStepNm;
  const double r = std::round(k);
  if (std::isfinite(k) && std::abs(k - r) <= 1e-9 && r >= 0 && r < kSpectralBands)
    return static_cast<int>(r);
  std::ostringstream os;
  os << what << ": expected a wavelength of 400, 410, ..., 700 nm, found " << nm;
  throw std::invalid_argument(os.str());
}

Eigen::Vector3d cie1931_cmf(int k) {
  if (k < 0 || k >= kSpectralBands)
    throw std::out_of_range("cie1931_cmf: expected band 0..30, found " + std::to_string(k));
  return Eigen::Vector3d(kCmf[k][0], kCmf[k][1], kCmf[k][2]);
}

Eigen::Matrix3d xyz_to_linear_srgb() {
  // sRGB primaries and D65 white (IEC 61966-2-1 / ITU-R BT.709 chromaticities).
  Eigen::Matrix3d p;
  p.col(0) = xyz_of_chromaticity(0.64, 0.33);
  p.col(1) = xyz_of_chromaticity(0.30, 0.60);
  p.col(2) = xyz_of_chromaticity(0.15, 0.06);
  const Eigen::Vector3d white = xyz_of_chromaticity(0.3127, 0.3290);
  // Scale the primaries so that RGB (1, 1, 1) is the white point.
  const Eigen::Vector3d s = p.partialPivLu().solve(white);
  const Eigen::Matrix3d rgb_to_xyz = p * s.asDiagonal();
  return rgb_to_xyz.inverse();
}

Eigen::Matrix<double, 3, kSpectralBands> spectrum_to_rgb_matrix() {
  Eigen::Matrix<double, 3, kSpectralBands> xyz;
  for (int k = 0; k < kSpectralBands; ++k) xyz.col(k) = cie1931_cmf(k);
  Eigen::Matrix<double, 3, kSpectralBands> m = xyz_to_linear_srgb() * xyz;
  // White balance: a flat spectrum of 1 must give (1, 1, 1).
  const Eigen::Vector3d flat = m.rowwise().sum();
  for (int c = 0; c < 3; ++c) m.row(c) /= flat[c];
  return m;
}

Eigen::Vector3d rgb_luminance_weights() {
  // rgb = D^-1 A xyz_raw with A = xyz_to_linear_srgb(), D = diag(A * sum of
  // the CMFs); so Y_raw = row 1 of (A^-1 D) times rgb, and Y = Y_raw / sum ybar.
  Eigen::Vector3d cmf_sum = Eigen::Vector3d::Zero();
  for (int k = 0; k < kSpectralBands; ++k) cmf_sum += cie1931_cmf(k);
  const Eigen::Matrix3d a = xyz_to_linear_srgb();
  const Eigen::Vector3d d = a * cmf_sum;
  const Eigen::Matrix3d back = a.inverse() * d.asDiagonal();
  return back.row(1).transpose() / cmf_sum[1];
}

bool desaturate_into_gamut(Rgb& rgb, const Eigen::Vector3d& w, double floor) {
  const double lo = rgb.minCoeff();
  const double y = w.dot(rgb.matrix());
  if (!(lo < 0.0) && !(lo < floor * y)) return false;
  if (!(y > 0.0)) {
    rgb = Rgb::Zero();
    return true;
  }
  // Y + t (lo - Y) = floor Y for the smallest channel.
  const double t = y * (1.0 - floor) / (y - lo);
  rgb = (y + t * (rgb - y)).max(floor * y);  // max() only removes rounding residue
  return true;
}

Rgb spectrum_to_rgb(const Eigen::Matrix<double, 3, kSpectralBands>& m, const double* spectrum) {
  const Eigen::Map<const Eigen::Matrix<double, kSpectralBands, 1>> s(spectrum);
  return (m * s).array();
}

}  // namespace bf
