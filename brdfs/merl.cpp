// MERL .binary reader/writer, MERL half/difference angles and MerlBrdf (see merl.h).
#include "brdfs/merl.h"

#include "brdfs/temp_file.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bf {

namespace {

// Little-endian encoding regardless of the host byte order.
uint32_t load_u32_le(const unsigned char* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}
void store_u32_le(uint32_t v, unsigned char* p) {
  for (int b = 0; b < 4; ++b) p[b] = static_cast<unsigned char>(v >> (8 * b));
}
uint64_t byteswap64(uint64_t v) {
  uint64_t r = 0;
  for (int b = 0; b < 8; ++b) r |= ((v >> (8 * b)) & 0xFF) << (8 * (7 - b));
  return r;
}
// Converts doubles between host order and little-endian, in place.
void host_le_doubles(std::vector<double>& v) {
  if constexpr (std::endian::native == std::endian::little) return;
  for (double& d : v) {
    uint64_t u;
    std::memcpy(&u, &d, 8);
    u = byteswap64(u);
    std::memcpy(&d, &u, 8);
  }
}

const char* const kChannel[3] = {"red", "green", "blue"};

std::string bin_of(size_t cell) {
  const size_t p = cell % kMerlPhiD, d = (cell / kMerlPhiD) % kMerlThetaD,
               h = cell / (size_t{kMerlPhiD} * kMerlThetaD);
  return "theta_h bin " + std::to_string(h) + ", theta_d bin " + std::to_string(d) +
         ", phi_d bin " + std::to_string(p);
}

// Rotation about +z by angle a (right-handed).
Vec3 rotate_z(const Vec3& v, double c, double s) {
  return Vec3(c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z());
}
// Rotation about +y by angle a (right-handed: z towards x).
Vec3 rotate_y(const Vec3& v, double c, double s) {
  return Vec3(c * v.x() + s * v.z(), v.y(), -s * v.x() + c * v.z());
}

double fold_phi_d(double phi_d) {
  // f(phi_d) = f(phi_d + pi): bring into [0, pi).
  double p = std::fmod(phi_d, M_PI);
  if (p < 0.0) p += M_PI;
  if (p >= M_PI) p = 0.0;
  return p;
}

}  // namespace

MerlAngles merl_half_diff(const Vec3& wi, const Vec3& wo) {
  Vec3 h = wi + wo;
  const double len = h.norm();
  h = len > 1e-300 ? Vec3(h / len) : Vec3(0, 0, 1);
  MerlAngles a;
  const double rho = std::hypot(h.x(), h.y());
  a.theta_h = std::atan2(rho, h.z());
  // phi_h is undefined at h = n; rounding in wi + wo must not pick a random
  // one there, so it snaps to 0 (as atan2(0, 0) does for exact mirror pairs).
  const double phi_h = rho > 1e-12 ? std::atan2(h.y(), h.x()) : 0.0;
  // d = rotate(rotate(wi, n, -phi_h), b, -theta_h)
  const Vec3 t = rotate_z(wi, std::cos(phi_h), -std::sin(phi_h));
  const Vec3 d = rotate_y(t, std::cos(a.theta_h), -std::sin(a.theta_h));
  a.theta_d = std::atan2(std::hypot(d.x(), d.y()), d.z());
  a.phi_d = std::atan2(d.y(), d.x());
  return a;
}

void merl_half_diff_inverse(const MerlAngles& a, Vec3& wi, Vec3& wo) {
  const double st = std::sin(a.theta_d);
  const Vec3 d(st * std::cos(a.phi_d), st * std::sin(a.phi_d), std::cos(a.theta_d));
  const double ch = std::cos(a.theta_h), sh = std::sin(a.theta_h);
  wi = rotate_y(d, ch, sh);
  const Vec3 h(sh, 0.0, ch);
  wo = 2.0 * wi.dot(h) * h - wi;
}

int merl_theta_h_index(double theta_h) {
  if (!(theta_h > 0.0)) return 0;
  const double x = std::sqrt(theta_h / (M_PI / 2) * kMerlThetaH * kMerlThetaH);
  if (!(x < kMerlThetaH - 1)) return kMerlThetaH - 1;
  return static_cast<int>(x);
}

int merl_theta_d_index(double theta_d) {
  const double x = theta_d / (M_PI / 2) * kMerlThetaD;
  if (!(x > 0.0)) return 0;
  if (!(x < kMerlThetaD - 1)) return kMerlThetaD - 1;
  return static_cast<int>(x);
}

int merl_phi_d_index(double phi_d) {
  if (!std::isfinite(phi_d)) return 0;
  const double x = fold_phi_d(phi_d) / M_PI * kMerlPhiD;
  if (!(x > 0.0)) return 0;
  if (!(x < kMerlPhiD - 1)) return kMerlPhiD - 1;
  return static_cast<int>(x);
}

double merl_theta_h_centre(int i) {
  const double u = (i + 0.5) / kMerlThetaH;
  return u * u * (M_PI / 2);
}
double merl_theta_d_centre(int j) {
  return (j + 0.5) / kMerlThetaD * (M_PI / 2);
}
double merl_phi_d_centre(int k) {
  return (k + 0.5) / kMerlPhiD * M_PI;
}

size_t MerlTable::missing_count() const {
  size_t n = 0;
  for (size_t c = 0; c < kMerlCells; ++c) n += missing(c) ? 1 : 0;
  return n;
}

MerlTable read_merl(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw std::invalid_argument(path + ": merl: expected a regular file, found " +
                                (fs::exists(path, ec) ? "something else (a folder?)" : "nothing"));
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) throw std::runtime_error(path + ": merl: cannot read file size: " + ec.message());
  if (size < 12)
    throw std::invalid_argument(path +
                                ": merl: expected a 12-byte header (three int32 dims), "
                                "file has " +
                                std::to_string(size) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": merl: cannot open file");
  unsigned char header[12];
  in.read(reinterpret_cast<char*>(header), 12);
  if (in.gcount() != 12) throw std::runtime_error(path + ": merl: cannot read the header");
  int64_t dims[3];
  for (int k = 0; k < 3; ++k) dims[k] = static_cast<int32_t>(load_u32_le(header + 4 * k));
  const int64_t want[3] = {kMerlThetaH, kMerlThetaD, kMerlPhiD};
  for (int k = 0; k < 3; ++k)
    if (dims[k] != want[k])
      throw std::invalid_argument(path + ": merl: expected dims 90 90 180, found " +
                                  std::to_string(dims[0]) + " " + std::to_string(dims[1]) + " " +
                                  std::to_string(dims[2]) + " (dims[" + std::to_string(k) +
                                  "] should be " + std::to_string(want[k]) + ")");
  const uint64_t doubles = (size - 12) / 8;
  if (size != kMerlFileBytes)
    throw std::invalid_argument(
        path + ": merl: expected 90*90*180*3 = 4374000 doubles (" + std::to_string(kMerlFileBytes) +
        " bytes with the header), file has " + std::to_string(doubles) + " doubles (" +
        std::to_string(size) + " bytes)" + (size < kMerlFileBytes ? " (truncated?)" : ""));
  MerlTable t;
  t.raw.resize(3 * kMerlCells);
  in.read(reinterpret_cast<char*>(t.raw.data()),
          static_cast<std::streamsize>(t.raw.size() * sizeof(double)));
  if (in.gcount() != static_cast<std::streamsize>(t.raw.size() * sizeof(double)))
    throw std::runtime_error(path + ": merl: expected 4374000 doubles, could read only " +
                             std::to_string(in.gcount() / 8));
  host_le_doubles(t.raw);
  for (size_t i = 0; i < t.raw.size(); ++i)
    if (!std::isfinite(t.raw[i])) {
      std::ostringstream os;
      os << path << ": merl: expected finite values, found " << t.raw[i] << " in the "
         << kChannel[i / kMerlCells] << " block at " << bin_of(i % kMerlCells) << " (double #" << i
         << ")";
      throw std::invalid_argument(os.str());
    }
  return t;
}

void write_merl(const MerlTable& table, const std::string& path) {
  if (table.raw.size() != 3 * kMerlCells)
    throw std::invalid_argument(path + ": merl: expected a table of 4374000 doubles, found " +
                                std::to_string(table.raw.size()));
  for (size_t i = 0; i < table.raw.size(); ++i)
    if (!std::isfinite(table.raw[i]))
      throw std::invalid_argument(path + ": merl: refusing to write a non-finite value in the " +
                                  kChannel[i / kMerlCells] + " block at " + bin_of(i % kMerlCells));
  const std::string tmp = create_unique_temp(path);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(path + ": merl: cannot open " + tmp + " for writing");
    unsigned char header[12];
    const uint32_t dims[3] = {kMerlThetaH, kMerlThetaD, kMerlPhiD};
    for (int k = 0; k < 3; ++k) store_u32_le(dims[k], header + 4 * k);
    out.write(reinterpret_cast<const char*>(header), 12);
    if constexpr (std::endian::native == std::endian::little) {
      out.write(reinterpret_cast<const char*>(table.raw.data()),
                static_cast<std::streamsize>(table.raw.size() * sizeof(double)));
    } else {
      std::vector<double> le = table.raw;
      host_le_doubles(le);
      out.write(reinterpret_cast<const char*>(le.data()),
                static_cast<std::streamsize>(le.size() * sizeof(double)));
    }
    out.flush();
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw std::runtime_error(path + ": merl: write failed (disk full?)");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw std::runtime_error(path + ": merl: cannot rename temporary file: " + ec.message());
  }
}

MerlTable merl_tabulate(const Brdf& brdf, MerlTabulateStats* stats) {
  MerlTable t;
  t.raw.assign(3 * kMerlCells, -1.0);
  MerlTabulateStats st;
  st.cells = kMerlCells;
  for (int h = 0; h < kMerlThetaH; ++h)
    for (int d = 0; d < kMerlThetaD; ++d)
      for (int p = 0; p < kMerlPhiD; ++p) {
        const size_t cell = merl_cell(h, d, p);
        Vec3 wi, wo;
        merl_half_diff_inverse(
            {merl_theta_h_centre(h), merl_theta_d_centre(d), merl_phi_d_centre(p)}, wi, wo);
        if (!(wi.z() > 0.0) || !(wo.z() > 0.0)) {
          ++st.below_horizon;
          continue;
        }
        const Rgb f = brdf.eval(wi, wo);
        if (!f.isFinite().all() || (f < 0.0).any()) {
          ++st.invalid;
          continue;
        }
        for (int c = 0; c < 3; ++c) t.raw[c * kMerlCells + cell] = f[c] / kMerlScale[c];
        // A value so large that dividing by the scale overflows is invalid too.
        if (!std::isfinite(t.raw[cell]) || !std::isfinite(t.raw[kMerlCells + cell]) ||
            !std::isfinite(t.raw[2 * kMerlCells + cell])) {
          for (int c = 0; c < 3; ++c) t.raw[c * kMerlCells + cell] = -1.0;
          ++st.invalid;
        }
      }
  if (stats) *stats = st;
  return t;
}

MerlLookup parse_merl_lookup(const std::string& s, const std::string& what) {
  if (s == "nearest") return MerlLookup::Nearest;
  if (s == "linear") return MerlLookup::Linear;
  throw std::invalid_argument(what + ": lookup expected 'nearest' or 'linear', found '" + s + "'");
}

MerlBrdf::MerlBrdf(std::shared_ptr<const MerlTable> table, MerlLookup lookup, std::string source)
    : table_(std::move(table)), lookup_(lookup), source_(std::move(source)) {
  if (!table_ || table_->raw.size() != 3 * kMerlCells)
    throw std::invalid_argument("merl: expected a table of 4374000 doubles");
}

Rgb MerlBrdf::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  return lookup_value(wi, wo).value_or(Rgb::Zero());
}

bool MerlBrdf::defined_at(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return true;  // 0 below the horizon is the BRDF's value
  return lookup_value(wi, wo).has_value();
}

std::optional<Rgb> MerlBrdf::lookup_value(const Vec3& wi, const Vec3& wo) const {
  const MerlAngles a = merl_half_diff(wi, wo);
  const MerlTable& t = *table_;
  if (lookup_ == MerlLookup::Nearest) {
    const size_t cell = merl_cell(merl_theta_h_index(a.theta_h), merl_theta_d_index(a.theta_d),
                                  merl_phi_d_index(a.phi_d));
    if (t.missing(cell)) return std::nullopt;
    return t.value(cell);
  }
  // Continuous index coordinates; bin centres sit at integers.
  const double u = std::clamp(kMerlThetaH * std::sqrt(std::max(a.theta_h, 0.0) / (M_PI / 2)) - 0.5,
                              0.0, double(kMerlThetaH - 1));
  const double v =
      std::clamp(a.theta_d / (M_PI / 2) * kMerlThetaD - 0.5, 0.0, double(kMerlThetaD - 1));
  const double w = fold_phi_d(std::isfinite(a.phi_d) ? a.phi_d : 0.0) / M_PI * kMerlPhiD - 0.5;
  const int h0 = std::min(static_cast<int>(u), kMerlThetaH - 2);
  const int d0 = std::min(static_cast<int>(v), kMerlThetaD - 2);
  const int p0 = static_cast<int>(std::floor(w));
  const double th = u - h0, td = v - d0, tp = w - p0;
  Rgb sum = Rgb::Zero();
  double wsum = 0.0;
  for (int dh = 0; dh < 2; ++dh)
    for (int dd = 0; dd < 2; ++dd)
      for (int dp = 0; dp < 2; ++dp) {
        const double wt = (dh ? th : 1 - th) * (dd ? td : 1 - td) * (dp ? tp : 1 - tp);
        if (wt <= 0.0) continue;
        const int p = ((p0 + dp) % kMerlPhiD + kMerlPhiD) % kMerlPhiD;
        const size_t cell = merl_cell(h0 + dh, d0 + dd, p);
        if (t.missing(cell)) continue;
        sum += wt * t.value(cell);
        wsum += wt;
      }
  if (!(wsum > 1e-12)) return std::nullopt;
  return Rgb(sum / wsum);
}

std::string MerlBrdf::to_string() const {
  return "merl(" + source_ + ", lookup=" + (lookup_ == MerlLookup::Nearest ? "nearest" : "linear") +
         ")";
}

double merl_cell_measure(int h, int d, int nh, int nd, int np) {
  const double lo = double(h) / kMerlThetaH, hi = double(std::min(h + nh, kMerlThetaH)) / kMerlThetaH;
  const double dtheta_h = (hi * hi - lo * lo) * (M_PI / 2);  // theta_h = (index / 90)^2 pi / 2
  const double dtheta_d = double(std::min(d + nd, kMerlThetaD) - d) * (M_PI / 2) / kMerlThetaD;
  const double dphi_d = double(np) * M_PI / kMerlPhiD;
  const double th = merl_theta_h_centre(h), td = merl_theta_d_centre(d);
  return std::sin(th) * dtheta_h * std::sin(td) * std::cos(td) * dtheta_d * dphi_d;
}

SampleSet MerlBrdf::samples(int stride, bool measure_weights) const {
  if (stride < 1 || stride > kMerlThetaH)
    throw std::invalid_argument("merl samples: stride expected 1..90, found " +
                                std::to_string(stride));
  const MerlTable& t = *table_;
  SampleSet s;
  const size_t n = size_t((kMerlThetaH + stride - 1) / stride) *
                   ((kMerlThetaD + stride - 1) / stride) * ((kMerlPhiD + stride - 1) / stride);
  s.wi.reserve(n);
  s.wo.reserve(n);
  s.value.reserve(n);
  s.valid.reserve(n);
  for (int h = 0; h < kMerlThetaH; h += stride)
    for (int d = 0; d < kMerlThetaD; d += stride)
      for (int p = 0; p < kMerlPhiD; p += stride) {
        const size_t cell = merl_cell(h, d, p);
        Vec3 wi, wo;
        merl_half_diff_inverse(
            {merl_theta_h_centre(h), merl_theta_d_centre(d), merl_phi_d_centre(p)}, wi, wo);
        s.push(wi, wo, t.missing(cell) ? Rgb::Constant(-1.0) : t.value(cell),
               measure_weights ? merl_cell_measure(h, d, stride, stride, stride) : 1.0);
      }
  s.description = "merl table " + source_ + " (bin centres, stride " + std::to_string(stride) + ")";
  if (measure_weights) {
    // Mean 1 over the samples a fit uses, so the smoothing keeps its balance.
    double sum = 0.0;
    size_t n = 0;
    for (size_t k = 0; k < s.size(); ++k)
      if ((s.value[k] >= 0.0).all()) {
        sum += s.weight[k];
        ++n;
      }
    if (sum > 0.0)
      for (double& w : s.weight) w *= double(n) / sum;
    s.description += ", weighted by cell measure";
  }
  // The format stores an isotropic, reciprocal BRDF (phi_h dropped, phi_d folded
  // by reciprocity); it does not assume the mirror phi_d -> -phi_d.
  s.symmetries = {true, true, false};
  // A cell's phi_h = 0 is the format's storage convention: it stands for every azimuth.
  s.representatives = true;
  s.validate();
  return s;
}

}  // namespace bf
