// MeasuredBrdf (scattered-data interpolation), measured_samples(), and the
// catalogue's measured-file loaders and Cornell material models (see measured.h).
#include "brdfs/measured.h"
#include "brdfs/spectral.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "brdfs/catalogue.h"
#include "brdfs/merl.h"
#include "brdfs/sample_csv.h"

namespace bf {

namespace {

// A static 3D kd-tree over points, for k-nearest-neighbour queries.
class KdTree3 {
 public:
  explicit KdTree3(std::vector<Vec3> points) : pts_(std::move(points)) {
    idx_.resize(pts_.size());
    for (size_t i = 0; i < idx_.size(); ++i) idx_[i] = i;
    dim_.assign(pts_.size(), 0);
    build(0, idx_.size());
  }

  // The n nearest points as (squared distance, index), nearest first.
  void nearest(const Vec3& q, size_t n, std::vector<std::pair<double, size_t>>& best) const {
    best.clear();
    if (n == 0) return;
    search(0, idx_.size(), q, n, best);
  }

 private:
  void build(size_t lo, size_t hi) {
    if (hi - lo <= 1) return;
    Vec3 mn = pts_[idx_[lo]], mx = mn;
    for (size_t i = lo; i < hi; ++i) {
      mn = mn.cwiseMin(pts_[idx_[i]]);
      mx = mx.cwiseMax(pts_[idx_[i]]);
    }
    int dim = 0;
    (mx - mn).maxCoeff(&dim);
    const size_t mid = lo + (hi - lo) / 2;
    std::nth_element(idx_.begin() + lo, idx_.begin() + mid, idx_.begin() + hi,
                     [&](size_t a, size_t b) { return pts_[a][dim] < pts_[b][dim]; });
    dim_[mid] = static_cast<uint8_t>(dim);
    build(lo, mid);
    build(mid + 1, hi);
  }

  void search(size_t lo, size_t hi, const Vec3& q, size_t n,
              std::vector<std::pair<double, size_t>>& best) const {
    if (lo >= hi) return;
    const size_t mid = lo + (hi - lo) / 2;
    const size_t id = idx_[mid];
    const double d2 = (pts_[id] - q).squaredNorm();
    if (best.size() < n || d2 < best.back().first) {
      const std::pair<double, size_t> e{d2, id};
      best.insert(std::upper_bound(best.begin(), best.end(), e), e);
      if (best.size() > n) best.pop_back();
    }
    if (hi - lo == 1) return;
    const int dim = dim_[mid];
    const double diff = q[dim] - pts_[id][dim];
    const bool left_first = diff < 0.0;
    if (left_first)
      search(lo, mid, q, n, best);
    else
      search(mid + 1, hi, q, n, best);
    if (best.size() < n || diff * diff < best.back().first) {
      if (left_first)
        search(mid + 1, hi, q, n, best);
      else
        search(lo, mid, q, n, best);
    }
  }

  std::vector<Vec3> pts_;
  std::vector<size_t> idx_;
  std::vector<uint8_t> dim_;  // split dimension of the node whose point sits at idx_[i]
};

}  // namespace

struct MeasuredBrdf::Table {
  SampleSet samples;        // everything as measured (with validity)
  std::vector<Rgb> values;  // valid samples only, same order as the tree's points
  KdTree3 tree;
  Table(SampleSet s, std::vector<Vec3> points, std::vector<Rgb> v)
      : samples(std::move(s)), values(std::move(v)), tree(std::move(points)) {}
};

void MeasuredOptions::validate() const {
  if (neighbours < 1 || neighbours > 64)
    throw std::invalid_argument("measured: k (neighbours) expected 1..64, found " +
                                std::to_string(neighbours));
}

Vec3 marschner_point(const Vec3& wi, const Vec3& wo) {
  const double si = std::hypot(wi.x(), wi.y()), so = std::hypot(wo.x(), wo.y());
  // |phi_o - phi_i| in [0, pi] from the projections onto the surface plane.
  const double cross = wi.x() * wo.y() - wi.y() * wo.x();
  const double dot = wi.x() * wo.x() + wi.y() * wo.y();
  const double dphi = std::abs(std::atan2(cross, dot));
  return Vec3(si * so, wi.z() * wo.z(), dphi / M_PI);
}

MeasuredBrdf::MeasuredBrdf(std::string name, SampleSet samples, const MeasuredOptions& options)
    : name_(std::move(name)), options_(options) {
  options_.validate();
  if (samples.valid.size() != samples.size()) samples.validate();
  std::vector<Vec3> points;
  std::vector<Rgb> values;
  for (size_t k = 0; k < samples.size(); ++k) {
    if (!samples.valid[k]) continue;
    points.push_back(marschner_point(samples.wi[k], samples.wo[k]));
    values.push_back(samples.value[k]);
  }
  if (points.empty())
    throw std::invalid_argument(name_ + ": expected at least one valid sample, found none (" +
                                samples.summary() + ")");
  table_ = std::make_shared<const Table>(std::move(samples), std::move(points), std::move(values));
}

Rgb MeasuredBrdf::eval(const Vec3& wi, const Vec3& wo) const {
  if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
  const Table& t = *table_;
  const size_t count = t.values.size();
  const size_t k = std::min<size_t>(options_.neighbours, count);
  const size_t want = std::min(k + 1, count);
  std::vector<std::pair<double, size_t>> nb;
  nb.reserve(want + 1);
  t.tree.nearest(marschner_point(wi, wo), want, nb);
  // A query on a sample returns it (the mean if several coincide).
  constexpr double kExact2 = 1e-24;
  if (nb[0].first <= kExact2) {
    Rgb sum = Rgb::Zero();
    int n = 0;
    for (const auto& [d2, i] : nb)
      if (d2 <= kExact2) {
        sum += t.values[i];
        ++n;
      }
    return sum / n;
  }
  const double r = want > k ? std::sqrt(nb[k].first) : 2.0 * std::sqrt(nb[k - 1].first);
  Rgb sum = Rgb::Zero();
  double wsum = 0.0;
  for (size_t j = 0; j < k; ++j) {
    const double d = std::sqrt(nb[j].first);
    const double a = std::max(r - d, 0.0) / (r * d);
    const double w = a * a;
    sum += w * t.values[nb[j].second];
    wsum += w;
  }
  if (!(wsum > 0.0) || !std::isfinite(wsum)) {
    // All k neighbours tie with the (k+1)-th: equal weights.
    sum = Rgb::Zero();
    for (size_t j = 0; j < k; ++j) sum += t.values[nb[j].second];
    return sum / double(k);
  }
  return sum / wsum;
}

std::string MeasuredBrdf::to_string() const {
  std::ostringstream os;
  os << name_ << "(" << table_->samples.description << "; " << table_->values.size()
     << " valid samples; modified Shepard, k=" << options_.neighbours << ")";
  return os.str();
}

const SampleSet& MeasuredBrdf::samples() const {
  return table_->samples;
}

bool MeasuredBrdf::reciprocal() const { return table_->samples.symmetries.reciprocal; }
bool MeasuredBrdf::isotropic() const { return table_->samples.symmetries.isotropic; }
bool MeasuredBrdf::bilateral() const { return table_->samples.symmetries.bilateral; }

bool MeasuredBrdf::whole_domain(std::string* why) const {
  const Symmetries& d = table_->samples.symmetries;
  if (d.covers(interpolant_needs())) return true;
  if (why)
    *why = "the interpolant of " + name_ + " assumes isotropic+reciprocal+bilateral, its samples declare " +
           d.to_string();
  return false;
}

bool has_cell_measure(const Brdf& brdf) { return dynamic_cast<const MerlBrdf*>(&brdf) != nullptr; }

SampleSet measured_samples(const Brdf& brdf, bool measure_weights) {
  if (const auto* m = dynamic_cast<const MeasuredBrdf*>(&brdf)) {
    if (measure_weights)
      throw std::invalid_argument(brdf.to_string() +
                                  ": weights = \"measure\" needs a table whose cells have a known measure (a MERL "
                                  ".binary); expected weights = \"none\" or \"auto\" for scattered samples");
    return m->samples();
  }
  if (const auto* m = dynamic_cast<const MerlBrdf*>(&brdf)) return m->samples(1, measure_weights);
  throw std::invalid_argument(brdf.to_string() +
                              ": not a measured BRDF (expected one loaded from .astm, .brdf, "
                              ".csv or .binary); sample it with a grid or stratified set instead");
}

BrdfPtr measured_from_training(const Brdf& brdf, const SampleSet& train) {
  if (const auto* m = dynamic_cast<const MeasuredBrdf*>(&brdf))
    return std::make_shared<MeasuredBrdf>(m->name(), train, m->options());
  if (const auto* m = dynamic_cast<const MerlBrdf*>(&brdf)) {
    if (train.valid_count() == 0)
      throw std::invalid_argument(brdf.to_string() + ": no valid training sample to make a table of");
    auto t = std::make_shared<MerlTable>();
    t->raw.assign(3 * kMerlCells, -1.0);
    const MerlTable& full = m->table();
    for (size_t k = 0; k < train.size(); ++k) {
      if (!train.valid[k]) continue;
      const MerlAngles a = merl_half_diff(train.wi[k], train.wo[k]);
      const size_t cell = merl_cell(merl_theta_h_index(a.theta_h), merl_theta_d_index(a.theta_d),
                                    merl_phi_d_index(a.phi_d));
      for (int c = 0; c < 3; ++c) t->raw[c * kMerlCells + cell] = full.raw[c * kMerlCells + cell];
    }
    return std::make_shared<MerlBrdf>(t, MerlLookup::Linear, m->source() + " (training cells)");
  }
  return nullptr;
}

namespace {

MeasuredOptions read_measured_options(const ParamDict& options) {
  MeasuredOptions o;
  o.neighbours = options.get_int("k", o.neighbours);
  o.validate();
  return o;
}

struct SpectralOptions {
  int band = 0;  // 0 = RGB, else the band in nm
  double gamut_floor = kGamutFloor;  // brdfs/spectral.h
  MeasuredOptions measured;
};

// Reads the options band and k (marking them used).
SpectralOptions read_spectral_options(const ParamDict& options) {
  SpectralOptions o;
  o.band = options.get_int("band", 0);
  if (o.band != 0) spectral_band_index(o.band, options.origin() + ": band");
  o.gamut_floor = options.get_scalar("gamut_floor", kGamutFloor);
  if (!(o.gamut_floor >= 0.0 && o.gamut_floor <= 0.5))
    throw std::invalid_argument(options.origin() + ": gamut_floor: expected a fraction of the luminance in 0..0.5, found " +
                                std::to_string(o.gamut_floor));
  o.measured = read_measured_options(options);
  return o;
}

// A MeasuredBrdf from a file's samples; errors (e.g. every sample masked) name
// the file.
BrdfPtr make_measured(const std::string& path, const std::string& name, SampleSet samples,
                      const MeasuredOptions& o) {
  try {
    return std::make_shared<MeasuredBrdf>(name, std::move(samples), o);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

// Reads a spectral file (.astm or .brdf) into a MeasuredBrdf.
BrdfPtr load_spectral(const std::string& path, const SpectralOptions& o, const std::string& name,
                      bool astm) {
  const SpectralMeasurements m = astm ? read_astm(path) : read_pbrt_brdf(path);
  return make_measured(path, name, spectral_to_samples(m, o.band, nullptr, o.gamut_floor), o.measured);
}

const std::vector<ParamInfo> kSpectralParams = {
    {"band", "rgb",
     "a single band in nm (400, 410, ..., 700) in all three channels; "
     "absent: CIE 1931 -> linear sRGB, flat spectrum -> grey"},
    {"k", "8", "neighbours of the modified Shepard interpolation, 1..64"},
    {"gamut_floor", "0.01",
     "colour: every channel kept at >= this fraction of the sample's luminance by the gamut mapping, 0..0.5 "
     "(0: out-of-gamut colours end at the gamut's edge with a channel at exactly 0)"},
};

struct CornellMaterial {
  const char* name;
  const char* file;
  const char* what;
};
const CornellMaterial kCornell[] = {
    {"krylon-blue", "krylon_blue.astm",
     "Krylon spray enamel 'True Blue' with a medium-gloss overcoat (thesis's krylon blue)"},
    {"garnet-red", "garnet_red.astm",
     "Dupli-Color garnet red lacquer with a medium-gloss overcoat (thesis's garnet red)"},
    {"cayman", "cayman.astm", "Ford Cayman metallic lacquer, high gloss (thesis's cayman)"},
    {"acryl-blue", "acryl_blue.astm", "blue Lucite acrylic sheet"},
    {"mystique", "mystique.brdf", "Ford Mystic colour-shifting lacquer (pbrt-v2 .brdf file)"},
};

}  // namespace

void register_measured_loaders(Catalogue& cat) {
  cat.add_loader(".astm", [](const std::string& path, const ParamDict& options) -> BrdfPtr {
    const SpectralOptions o = read_spectral_options(options);
    options.check_unused("the .astm loader", {"band", "k", "gamut_floor"});
    return load_spectral(path, o, "astm", true);
  });
  cat.add_loader(".brdf", [](const std::string& path, const ParamDict& options) -> BrdfPtr {
    const SpectralOptions o = read_spectral_options(options);
    options.check_unused("the .brdf loader", {"band", "k", "gamut_floor"});
    return load_spectral(path, o, "brdf", false);
  });
  cat.add_loader(".csv", [](const std::string& path, const ParamDict& options) -> BrdfPtr {
    const MeasuredOptions o = read_measured_options(options);
    options.check_unused("the .csv loader", {"k"});
    return make_measured(path, "csv", read_sample_csv(path), o);
  });
  cat.add_loader(".binary", [](const std::string& path, const ParamDict& options) -> BrdfPtr {
    const MerlLookup lookup =
        parse_merl_lookup(options.get_string("lookup", "nearest"), options.origin());
    options.check_unused("the .binary (MERL) loader", {"lookup"});
    auto table = std::make_shared<const MerlTable>(read_merl(path));
    return std::make_shared<MerlBrdf>(std::move(table), lookup, path);
  });

  for (const CornellMaterial& c : kCornell) {
    const std::string name = c.name, file = c.file;
    const bool astm = file.size() > 5 && file.substr(file.size() - 5) == ".astm";
    cat.add_model({name,
                   std::string("Cornell measured spectral BRDF: ") + c.what +
                       ". 1439 scattered "
                       "samples, 31 bands, from <data>/cornell/" +
                       file + "; interpolated by modified Shepard in Marschner's isotropic space.",
                   kSpectralParams, [name, file, astm](const ParamDict& d) -> BrdfPtr {
                     const SpectralOptions o = read_spectral_options(d);
                     const std::string path = data_dir() + "/cornell/" + file;
                     if (!std::filesystem::exists(path))
                       throw std::invalid_argument(d.origin() + ": " + name + ": data file " +
                                                   path +
                                                   " not found (set BRDF_FACTOR_DATA "
                                                   "to the folder holding cornell/)");
                     return load_spectral(path, o, name, astm);
                   }});
  }
}

}  // namespace bf
