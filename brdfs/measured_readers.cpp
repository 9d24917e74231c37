// Readers of spectral scattered-sample files (Cornell ASTM E1392 .astm and
// pbrt-v2 .brdf) and their conversion to a SampleSet (see measured.h).
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "brdfs/file_check.h"
#include "brdfs/directions.h"
#include "brdfs/measured.h"
#include "brdfs/measured_text.h"

namespace bf {

namespace {

constexpr size_t kMaxLine = 1 << 16;
constexpr int kColumns = 4 + kSpectralBands;  // angles + bands
const char* const kAngleNames[4] = {"theta_i", "phi_i", "theta_s", "phi_s"};

std::string fmt(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::string column_name(int c) {
  if (c < 4) return kAngleNames[c];
  return fmt(spectral_band_nm(c - 4)) + "nm";
}

// Checks one record's angles; `at` is "path:line".
void check_angles(const std::string& at, const std::array<double, 4>& a) {
  constexpr double kTol = 1e-6;
  for (int c = 0; c < 4; ++c) {
    const bool theta = (c % 2) == 0;
    const double v = a[c];
    if (theta) {
      if (!(v >= 0.0 && v <= M_PI / 2 + kTol)) {
        // In (pi/2, pi] a direction below the surface (or a small angle in
        // degrees); beyond pi up to 90 most likely degrees.
        std::string hint = (v > M_PI / 2 && v <= M_PI) ? " (below the horizon, or degrees? the format stores radians)"
                           : (v > M_PI && v <= 90.0 + kTol) ? " (degrees? the format stores radians)"
                                                            : "";
        throw std::invalid_argument(at + ": " + kAngleNames[c] +
                                    " expected radians in [0, pi/2], found " + fmt(v) + hint);
      }
    } else {
      if (!(v >= -2 * M_PI - kTol && v <= 2 * M_PI + kTol)) {
        std::string hint =
            std::abs(v) <= 360.0 + kTol ? " (degrees? the format stores radians)" : "";
        throw std::invalid_argument(at + ": " + kAngleNames[c] +
                                    " expected radians in [-2pi, 2pi], found " + fmt(v) + hint);
      }
    }
  }
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> cells;
  size_t start = 0;
  for (;;) {
    const size_t p = s.find(sep, start);
    cells.push_back(
        text::strip(s.substr(start, p == std::string::npos ? std::string::npos : p - start)));
    if (p == std::string::npos) break;
    start = p + 1;
  }
  return cells;
}

bool is_header_key(const std::string& k) {
  if (k.empty()) return false;
  for (unsigned char c : k)
    if (!(std::isupper(c) || std::isdigit(c) || c == '_')) return false;
  return true;
}

void parse_vars(const std::string& at, const std::string& rest) {
  const std::vector<std::string> cells = split(rest, ',');
  if (cells.size() != static_cast<size_t>(kColumns))
    throw std::invalid_argument(at + ": VARS expected " + std::to_string(kColumns) +
                                " columns (theta_i,phi_i,theta_s,phi_s,400nm,410nm,...,700nm), "
                                "found " +
                                std::to_string(cells.size()));
  for (int c = 0; c < kColumns; ++c) {
    const std::string want = column_name(c);
    if (cells[c] != want)
      throw std::invalid_argument(at + ": VARS column " + std::to_string(c + 1) + " expected '" +
                                  want + "', found " + text::excerpt(cells[c]));
  }
}

void push_record(SpectralMeasurements& m, const std::string& at, const double* v) {
  if (m.size() >= kMaxMeasuredRecords)
    throw std::invalid_argument(at + ": expected at most " + std::to_string(kMaxMeasuredRecords) +
                                " records, found more");
  const std::array<double, 4> a{v[0], v[1], v[2], v[3]};
  check_angles(at, a);
  m.angles.push_back(a);
  m.values.insert(m.values.end(), v + 4, v + kColumns);
}

}  // namespace

SpectralMeasurements read_astm(const std::string& path) {
  check_regular_file(path, kMaxDataFileBytes, "ASTM file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open ASTM file");
  SpectralMeasurements m;
  m.path = path;
  long long num_points = -1;
  bool have_vars = false;
  size_t lineno = 0;
  std::string line;
  while (text::read_line(in, line, kMaxLine, path, lineno + 1)) {
    ++lineno;
    const std::string at = text::where(path, lineno);
    const std::string t = text::strip(line);
    if (t.empty()) continue;
    if (!have_vars) {
      const size_t sp = t.find_first_of(" \t");
      const std::string key = t.substr(0, sp);
      const std::string rest = sp == std::string::npos ? "" : text::strip(t.substr(sp));
      if (key == "VARS") {
        parse_vars(at, rest);
        have_vars = true;
        continue;
      }
      if (!is_header_key(key))
        throw std::invalid_argument(at +
                                    ": expected a header line 'KEY value' or 'VARS ...' "
                                    "before the data, found " +
                                    text::excerpt(t));
      if (key == "NUM_POINTS") {
        double n = 0;
        const bool ok = text::parse_number(rest, n) && n == std::floor(n) && n >= 1 &&
                        n <= static_cast<double>(kMaxMeasuredRecords);
        if (!ok)
          throw std::invalid_argument(at + ": NUM_POINTS expected an integer in 1.." +
                                      std::to_string(kMaxMeasuredRecords) + ", found " +
                                      text::excerpt(rest));
        num_points = static_cast<long long>(n);
      }
      if (key == "SAMPLE_NAME") m.sample_name = rest;
      continue;
    }
    const std::vector<std::string> cells = split(t, ',');
    if (cells.size() != static_cast<size_t>(kColumns))
      throw std::invalid_argument(at + ": expected " + std::to_string(kColumns) +
                                  " comma-separated values (4 angles, 31 bands), found " +
                                  std::to_string(cells.size()));
    double v[kColumns];
    for (int c = 0; c < kColumns; ++c) {
      if (!text::parse_number(cells[c], v[c]))
        throw std::invalid_argument(at + ": column " + std::to_string(c + 1) + " (" +
                                    column_name(c) + ") expected a number, found " +
                                    text::excerpt(cells[c]));
      if (!std::isfinite(v[c]))
        throw std::invalid_argument(at + ": column " + std::to_string(c + 1) + " (" +
                                    column_name(c) + ") expected a finite number, found " +
                                    text::excerpt(cells[c]));
    }
    push_record(m, at, v);
  }
  if (!have_vars)
    throw std::invalid_argument(path +
                                ": expected a line 'VARS theta_i,phi_i,theta_s,phi_s,"
                                "400nm,...,700nm', found none (not an ASTM E1392 file?)");
  if (m.size() == 0)
    throw std::invalid_argument(path + ": expected data rows after VARS, found none");
  if (num_points >= 0 && static_cast<long long>(m.size()) != num_points)
    throw std::invalid_argument(path + ": NUM_POINTS expected " + std::to_string(num_points) +
                                " data rows, found " + std::to_string(m.size()) +
                                " (truncated file?)");
  return m;
}

SpectralMeasurements read_pbrt_brdf(const std::string& path) {
  check_regular_file(path, kMaxDataFileBytes, "pbrt .brdf file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(path + ": cannot open pbrt .brdf file");
  SpectralMeasurements m;
  m.path = path;
  m.sample_name = std::filesystem::path(path).stem().string();
  enum Stage { kCount, kWavelengths, kRecords } stage = kCount;
  int wavelengths_read = 0;
  double record[kColumns];
  int in_record = 0;
  size_t record_line = 0;
  size_t lineno = 0;
  std::string line;
  while (text::read_line(in, line, kMaxLine, path, lineno + 1)) {
    ++lineno;
    const std::string at = text::where(path, lineno);
    const size_t hash = line.find('#');
    std::istringstream ts(hash == std::string::npos ? line : line.substr(0, hash));
    std::string tok;
    while (ts >> tok) {
      double v = 0;
      const bool number = text::parse_number(tok, v);
      if (stage == kCount) {
        if (!number || v != std::floor(v))
          throw std::invalid_argument(at + ": expected the number of wavelengths (31), found " +
                                      text::excerpt(tok));
        if (v != kSpectralBands)
          throw std::invalid_argument(at +
                                      ": expected 31 wavelengths (400..700 nm in 10 nm "
                                      "steps), found " +
                                      text::excerpt(tok));
        stage = kWavelengths;
        continue;
      }
      if (stage == kWavelengths) {
        const double want = spectral_band_nm(wavelengths_read);
        if (!number || v != want)
          throw std::invalid_argument(at + ": wavelength " + std::to_string(wavelengths_read + 1) +
                                      " expected " + fmt(want) + " nm, found " +
                                      text::excerpt(tok));
        if (++wavelengths_read == kSpectralBands) stage = kRecords;
        continue;
      }
      if (in_record == 0) record_line = lineno;
      const std::string name = column_name(in_record);
      if (!number)
        throw std::invalid_argument(at + ": record " + std::to_string(m.size() + 1) + " " + name +
                                    " expected a number, found " + text::excerpt(tok));
      if (!std::isfinite(v))
        throw std::invalid_argument(at + ": record " + std::to_string(m.size() + 1) + " " + name +
                                    " expected a finite number, found " + text::excerpt(tok));
      record[in_record++] = v;
      if (in_record == kColumns) {
        push_record(m, text::where(path, record_line), record);
        in_record = 0;
      }
    }
  }
  if (stage == kCount)
    throw std::invalid_argument(path +
                                ": expected the number of wavelengths (31), found end of "
                                "file");
  if (stage == kWavelengths)
    throw std::invalid_argument(path + ": expected 31 wavelengths, found " +
                                std::to_string(wavelengths_read) + " before the end of file");
  if (in_record != 0)
    throw std::invalid_argument(
        text::where(path, record_line) + ": record " + std::to_string(m.size() + 1) + " expected " +
        std::to_string(kColumns) +
        " numbers (4 angles, 31 values), "
        "found " +
        std::to_string(in_record) + " before the end of file (truncated file?)");
  if (m.size() == 0)
    throw std::invalid_argument(path +
                                ": expected at least one record after the wavelengths, "
                                "found none");
  return m;
}

SampleSet spectral_to_samples(const SpectralMeasurements& m, int band_nm, size_t* desaturated, double gamut_floor) {
  const int band = band_nm == 0 ? -1 : spectral_band_index(band_nm, m.path + ": band");
  const Eigen::Matrix<double, 3, kSpectralBands> to_rgb = spectrum_to_rgb_matrix();
  const Eigen::Vector3d luminance = rgb_luminance_weights();
  SampleSet s;
  size_t n_desaturated = 0;
  for (size_t k = 0; k < m.size(); ++k) {
    const std::array<double, 4>& a = m.angles[k];
    const double* spec = &m.values[k * kSpectralBands];
    Rgb v;
    if (band >= 0) {
      v = Rgb::Constant(spec[band] < 0.0 ? -1.0 : spec[band]);
    } else {
      bool negative = false;
      for (int b = 0; b < kSpectralBands; ++b) negative |= spec[b] < 0.0;
      v = negative ? Rgb::Constant(-1.0) : spectrum_to_rgb(to_rgb, spec);
      if (!negative && desaturate_into_gamut(v, luminance, gamut_floor)) ++n_desaturated;
    }
    s.push(from_spherical(a[0], a[1]), from_spherical(a[2], a[3]), v);
  }
  s.validate();
  std::ostringstream os;
  os << std::filesystem::path(m.path).filename().string();
  if (!m.sample_name.empty()) os << " '" << m.sample_name << "'";
  os << ", " << m.size() << " records, ";
  if (band >= 0)
    os << "band " << band_nm << " nm";
  else
    os << "rgb (CIE 1931 2deg, equal-energy white -> linear sRGB), " << n_desaturated
       << " desaturated into the sRGB gamut";
  if (band < 0 && gamut_floor > 0.0) os << ", every channel kept at >= " << gamut_floor * 100.0 << "% of the luminance";
  s.description = os.str();
  // ASTM (Cornell) and pbrt "irregular isotropic" files hold isotropic BRDFs
  // given as functions of (theta_i, theta_s, |phi_s - phi_i|): isotropic,
  // reciprocal and bilateral (the Cornell records cover phi_i = 0 and mostly
  // phi_s < 0, one half-slice of the domain).
  s.symmetries = Symmetries::all();
  if (desaturated) *desaturated = n_desaturated;
  return s;
}

}  // namespace bf
