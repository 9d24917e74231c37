// Tests of the spectral conversion, the Cornell .astm and pbrt .brdf readers,
// MeasuredBrdf's interpolation, the measured-data catalogue entries, and every
// failure kind of the readers (small bad files under tests/data/measured/).
#include "brdfs/measured.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "brdfs/models.h"
#include "brdfs/spectral.h"
#include "test_common.h"

using namespace bf;
using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;

using bf_test::TempDir;

std::string bad(const std::string& name) {
  return std::string(BF_TEST_DATA_DIR) + "/measured/" + name;
}
std::string cornell(const std::string& name) {
  return data_dir() + "/cornell/" + name;
}

using bf_test::run_cli_stderr;

double deg(double d) {
  return d * M_PI / 180.0;
}

// Writes the same synthetic records as an ASTM file and as a pbrt .brdf file.
void write_twin_files(const std::string& astm, const std::string& brdf,
                      const std::vector<std::array<double, 4>>& angles,
                      const std::vector<double>& values) {
  std::ofstream a(astm);
  a << "LAB_NAME Test lab\n\nSAMPLE_NAME Twin\nNUM_POINTS " << angles.size()
    << "\nVARS theta_i,phi_i,theta_s,phi_s";
  for (int b = 0; b < kSpectralBands; ++b) a << "," << 400 + 10 * b << "nm";
  a << "\n\n";
  std::ofstream p(brdf, std::ios::binary);
  p << "# twin of the ASTM file\r\n# num wls\r\n31\r\n# wls\r\n";
  for (int b = 0; b < kSpectralBands; ++b) p << 400 + 10 * b << (b == 18 ? "\r\n" : " ");
  p << "\r\n\r\n# records\r\n";
  a.setf(std::ios::fixed);
  p.setf(std::ios::fixed);
  a.precision(6);
  p.precision(6);
  for (size_t k = 0; k < angles.size(); ++k) {
    for (int c = 0; c < 4; ++c) {
      a << (c ? "," : "") << angles[k][c];
      p << angles[k][c] << " ";
    }
    for (int b = 0; b < kSpectralBands; ++b) {
      a << "," << values[k * kSpectralBands + b];
      // Records wrap over lines; a comment in between must not matter.
      p << values[k * kSpectralBands + b] << (b == 10 ? "  # mid-record comment\r\n" : " ");
    }
    a << "\n";
    p << "\r\n";
  }
}

}  // namespace

// ---------------------------------------------------------------- spectral

TEST_CASE("spectral: a flat spectrum maps to grey of the same value") {
  const auto m = spectrum_to_rgb_matrix();
  for (double v : {0.0, 1e-6, 0.3, 1.0, 645.8}) {
    std::vector<double> s(kSpectralBands, v);
    const Rgb rgb = spectrum_to_rgb(m, s.data());
    INFO("v = " << v << " rgb = " << rgb.transpose());
    for (int c = 0; c < 3; ++c) CHECK(bf_test::near_rel(rgb[c], v, 1e-12));
  }
  for (int c = 0; c < 3; ++c) CHECK(m.row(c).sum() == Approx(1.0).epsilon(1e-14));
}

TEST_CASE("spectral: CIE table and sRGB matrix match the published values") {
  // Spot checks of the typed-in table (CIE 15:2004).
  CHECK(cie1931_cmf(0).isApprox(Eigen::Vector3d(0.014310, 0.000396, 0.067850)));
  CHECK(cie1931_cmf(15).isApprox(Eigen::Vector3d(0.433450, 0.994950, 0.008750)));
  CHECK(cie1931_cmf(30).isApprox(Eigen::Vector3d(0.011359, 0.004102, 0.0)));
  CHECK(spectral_band_nm(15) == 550.0);
  // Equal-energy white over 400..700 nm is close to x = y = 1/3.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int k = 0; k < kSpectralBands; ++k) sum += cie1931_cmf(k);
  CHECK(sum.x() / sum.sum() == Approx(1.0 / 3).margin(0.005));
  CHECK(sum.y() / sum.sum() == Approx(1.0 / 3).margin(0.005));
  // IEC 61966-2-1 XYZ -> linear sRGB, 4 decimals.
  Eigen::Matrix3d published;
  published << 3.2406, -1.5372, -0.4986, -0.9689, 1.8758, 0.0415, 0.0557, -0.2040, 1.0570;
  CHECK((xyz_to_linear_srgb() - published).cwiseAbs().maxCoeff() < 1e-3);
  // Luminance weights sum to 1 (flat spectrum v has Y = v).
  CHECK(rgb_luminance_weights().sum() == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("spectral: narrow-band spectra get the expected hue, desaturated into gamut") {
  const auto m = spectrum_to_rgb_matrix();
  const Eigen::Vector3d w = rgb_luminance_weights();
  auto band_rgb = [&](double nm) {
    std::vector<double> s(kSpectralBands, 0.0);
    s[spectral_band_index(nm, "test")] = 1.0;
    return spectrum_to_rgb(m, s.data());
  };
  const Rgb blue = band_rgb(450), green = band_rgb(530), red = band_rgb(620);
  CHECK(blue[2] > blue[0]);
  CHECK(blue[2] > blue[1]);
  CHECK(green[1] > green[0]);
  CHECK(green[1] > green[2]);
  CHECK(red[0] > red[1]);
  CHECK(red[0] > red[2]);
  for (Rgb v : {blue, green, red}) {
    const double y = w.dot(v.matrix());
    REQUIRE(v.minCoeff() < 0.0);  // monochromatic light is outside the sRGB gamut
    Rgb g = v;
    CHECK(desaturate_into_gamut(g, w));
    CHECK(g.minCoeff() == Approx(0.0).margin(1e-15));
    CHECK(w.dot(g.matrix()) == Approx(y).epsilon(1e-12));  // luminance kept
    // Same hue: the largest channel stays the largest.
    Eigen::Index a, b;
    v.maxCoeff(&a);
    g.maxCoeff(&b);
    CHECK(a == b);
  }
  Rgb inside(0.2, 0.3, 0.4);
  CHECK_FALSE(desaturate_into_gamut(inside, w));
  CHECK(inside.isApprox(Rgb(0.2, 0.3, 0.4)));
}

TEST_CASE("spectral: band index accepts only the 31 bands") {
  CHECK(spectral_band_index(400, "x") == 0);
  CHECK(spectral_band_index(700, "x") == 30);
  CHECK_THROWS_WITH(spectral_band_index(555, "band"),
                    Contains("band: expected a wavelength of 400, 410, ..., 700 nm, found 555"));
  CHECK_THROWS_WITH(spectral_band_index(390, "band"), Contains("found 390"));
  CHECK_THROWS_WITH(spectral_band_index(std::nan(""), "band"), Contains("found nan"));
}

// ---------------------------------------------------------------- Cornell data

TEST_CASE("astm: the four Cornell files have 1439 samples and the README's maxima") {
  struct Case {
    const char* file;
    const char* sample_name;
    double max_all;  // README "max BRDF (1/sr)": the maximum over all 31 bands
    double max_550;  // maximum of the 550 nm band
  };
  // max_550 values read from the files (the README's column is over all bands).
  const Case cases[] = {{"acryl_blue.astm", "Blue Lucite", 29.8, 24.104004},
                        {"cayman.astm", "Cayman Metallic", 645.8, 631.320435},
                        {"garnet_red.astm", "Garnet Red", 38.4, 28.095280},
                        {"krylon_blue.astm", "Krylon Blue", 66.5, 34.776098}};
  for (const Case& c : cases) {
    INFO(c.file);
    const SpectralMeasurements m = read_astm(cornell(c.file));
    REQUIRE(m.size() == 1439);
    REQUIRE(m.values.size() == 1439 * size_t{kSpectralBands});
    CHECK(m.sample_name == c.sample_name);
    const double max_all = *std::max_element(m.values.begin(), m.values.end());
    CHECK(max_all == Approx(c.max_all).margin(0.05));
    CHECK(*std::min_element(m.values.begin(), m.values.end()) == 0.0);
    size_t arg = 0;
    for (size_t k = 0; k < m.size(); ++k)
      if (m.values[k * kSpectralBands + 15] > m.values[arg * kSpectralBands + 15]) arg = k;
    CHECK(m.values[arg * kSpectralBands + 15] == Approx(c.max_550).epsilon(1e-9));
    // The 550 nm maximum sits in the mirror direction: theta_i = 80 deg,
    // theta_s = 79 deg on the other side (phi_s = pi, phi_i = 0).
    CHECK(m.angles[arg][0] == Approx(deg(80)).margin(1e-5));
    CHECK(m.angles[arg][1] == 0.0);
    CHECK(m.angles[arg][2] == Approx(deg(79.05)).margin(deg(0.1)));
    CHECK(m.angles[arg][3] == Approx(M_PI).margin(1e-5));
    // Structure: phi_i always 0, 8 incident and 10 outgoing zenith angles.
    std::set<long> ti, ts;
    for (const auto& a : m.angles) {
      CHECK(a[1] == 0.0);
      ti.insert(std::lround(a[0] * 1e4));
      ts.insert(std::lround(a[2] * 1e4));
    }
    CHECK(ti.size() == 8);
    CHECK(ts.size() == 10);
  }
}

TEST_CASE("brdf: mystique parses to 1439 records with the Cornell angle set") {
  const SpectralMeasurements my = read_pbrt_brdf(cornell("mystique.brdf"));
  REQUIRE(my.size() == 1439);
  CHECK(*std::max_element(my.values.begin(), my.values.end()) == Approx(655.2).margin(0.05));
  // Same angle tuples as the .astm files (pbrt-v2's files carry the same measurements).
  const SpectralMeasurements cay = read_astm(cornell("cayman.astm"));
  auto key = [](const std::array<double, 4>& a) {
    return std::array<long, 4>{std::lround(a[0] * 1e6), std::lround(a[1] * 1e6),
                               std::lround(a[2] * 1e6), std::lround(a[3] * 1e6)};
  };
  std::set<std::array<long, 4>> a, b;
  for (const auto& x : my.angles) a.insert(key(x));
  for (const auto& x : cay.angles) b.insert(key(x));
  CHECK(a.size() == 1439);  // no duplicate tuples
  CHECK(a == b);
  size_t arg = 0;
  for (size_t k = 0; k < my.size(); ++k)
    if (my.values[k * kSpectralBands + 15] > my.values[arg * kSpectralBands + 15]) arg = k;
  CHECK(my.angles[arg][0] == Approx(deg(80)).margin(1e-5));
  CHECK(my.angles[arg][3] == Approx(M_PI).margin(1e-5));
}

TEST_CASE("astm/brdf: identical data in both formats parse to the same samples") {
  TempDir d("twin");
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<std::array<double, 4>> angles;
  std::vector<double> values;
  for (int k = 0; k < 40; ++k) {
    angles.push_back({std::round(U(rng) * 1.5e6) / 1e6, 0.0, std::round(U(rng) * 1.5e6) / 1e6,
                      std::round((U(rng) * 2 - 1) * 3.1e6) / 1e6});
    for (int b = 0; b < kSpectralBands; ++b) values.push_back(std::round(U(rng) * 5e6) / 1e6);
  }
  write_twin_files(d.file("twin.astm"), d.file("twin.brdf"), angles, values);
  const SpectralMeasurements a = read_astm(d.file("twin.astm"));
  const SpectralMeasurements b = read_pbrt_brdf(d.file("twin.brdf"));
  REQUIRE(a.size() == 40);
  REQUIRE(b.size() == 40);
  CHECK(a.angles == b.angles);
  CHECK(a.values == b.values);
  CHECK(a.sample_name == "Twin");
  for (int band : {0, 550}) {
    const SampleSet sa = spectral_to_samples(a, band), sb = spectral_to_samples(b, band);
    REQUIRE(sa.size() == sb.size());
    for (size_t k = 0; k < sa.size(); ++k) {
      CHECK(sa.wi[k] == sb.wi[k]);
      CHECK(sa.wo[k] == sb.wo[k]);
      CHECK((sa.value[k] == sb.value[k]).all());
    }
  }
  // Through the catalogue, both formats give the same BRDF values.
  const BrdfPtr ba = Catalogue::builtin().make(d.file("twin.astm"));
  const BrdfPtr bb = Catalogue::builtin().make(d.file("twin.brdf"));
  const Vec3 wi = from_spherical(0.4, 0.2), wo = from_spherical(0.9, 2.5);
  CHECK((ba->eval(wi, wo) == bb->eval(wi, wo)).all());
}

TEST_CASE("astm: samples follow the mirror-direction convention") {
  const BrdfPtr cay = Catalogue::builtin().make("cayman");
  const SampleSet s = measured_samples(*cay);
  REQUIRE(s.size() == 1439);
  REQUIRE(s.valid_count() == 1439);
  // The brightest sample: wo is (nearly) the mirror of wi about n.
  size_t arg = 0;
  for (size_t k = 0; k < s.size(); ++k)
    if (s.value[k].sum() > s.value[arg].sum()) arg = k;
  const Vec3 mirror(-s.wi[arg].x(), -s.wi[arg].y(), s.wi[arg].z());
  CHECK(std::acos(std::min(1.0, mirror.dot(s.wo[arg]))) < deg(1.0));
  // The measured peak is reproduced; the retro direction is far darker.
  const Vec3 wi = from_spherical(deg(80), 0.0);
  CHECK(cay->eval(s.wi[arg], s.wo[arg]).isApprox(s.value[arg], 1e-12));
  const Rgb peak = cay->eval(wi, from_spherical(deg(79.05), M_PI));
  const Rgb retro = cay->eval(wi, from_spherical(deg(79.05), 0.0));
  INFO("peak " << peak.transpose() << " retro " << retro.transpose());
  CHECK(peak.minCoeff() > 500.0);
  CHECK(retro.maxCoeff() < 0.01 * peak.minCoeff());
  // band=550 puts the 550 nm value in all three channels.
  const BrdfPtr c550 = Catalogue::builtin().make("cayman:band=550");
  const Rgb v = c550->eval(s.wi[arg], s.wo[arg]);
  CHECK(v[0] == Approx(631.320435).epsilon(1e-9));
  CHECK(v[0] == v[1]);
  CHECK(v[1] == v[2]);
}

TEST_CASE("catalogue: Cornell material names load, with band and k options") {
  const Catalogue& cat = Catalogue::builtin();
  for (const char* name : {"krylon-blue", "garnet-red", "cayman", "acryl-blue", "mystique"}) {
    INFO(name);
    REQUIRE(cat.models().count(name) == 1);
    const BrdfPtr b = cat.make(name);
    CHECK(b->name() == name);
    CHECK(measured_samples(*b).size() == 1439);
    const Rgb f = b->eval(from_spherical(0.5, 0.0), from_spherical(0.6, 2.0));
    CHECK(f.isFinite().all());
    CHECK((f >= 0.0).all());
    CHECK((f > 0.0).any());
  }
  CHECK(cat.make("mystique:band=700,k=3")->to_string().find("band 700 nm") != std::string::npos);
  CHECK_THROWS_WITH(cat.make("cayman:band=555"), Contains("found 555"));
  CHECK_THROWS_WITH(cat.make("cayman:k=0"), Contains("k (neighbours) expected 1..64, found 0"));
  CHECK_THROWS_WITH(cat.make("cayman:colour=1"), Contains("unknown parameter 'colour'"));
  CHECK_THROWS_WITH(cat.make(cornell("cayman.astm") + ":lookup=linear"),
                    Contains("unknown parameter 'lookup'"));
  CHECK_THROWS_WITH(cat.make(cornell("cayman.astm") + ":band=rgb"), Contains("band"));
  CHECK_THROWS_WITH(measured_samples(*cat.make("lambert")), Contains("not a measured BRDF"));
}

// ---------------------------------------------------------------- interpolation

TEST_CASE("measured: interpolation reproduces samples, is reciprocal, isotropic, bounded") {
  const BrdfPtr b = Catalogue::builtin().make("krylon-blue");
  const SampleSet s = measured_samples(*b);
  Rgb lo = s.value[0], hi = s.value[0];
  for (size_t k = 0; k < s.size(); ++k) {
    lo = lo.min(s.value[k]);
    hi = hi.max(s.value[k]);
    if (k % 7 == 0) CHECK(b->eval(s.wi[k], s.wo[k]).isApprox(s.value[k], 1e-12));
  }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 500; ++k) {
    const Vec3 wi = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const Vec3 wo = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const Rgb f = b->eval(wi, wo);
    INFO("wi=" << wi.transpose() << " wo=" << wo.transpose() << " f=" << f.transpose());
    REQUIRE(f.isFinite().all());
    CHECK((f >= lo - 1e-12).all());
    CHECK((f <= hi + 1e-12).all());
    CHECK((b->eval(wo, wi) - f).abs().maxCoeff() <= 1e-12 * (1 + f.maxCoeff()));
    const Eigen::AngleAxisd rot(2 * M_PI * U(rng), Vec3::UnitZ());
    const Rgb g = b->eval(rot * wi, rot * wo);
    CHECK((g - f).abs().maxCoeff() <= 1e-9 * (1 + f.maxCoeff()));
    // Bilateral symmetry: mirroring both about the x-z plane.
    const Rgb h = b->eval(Vec3(wi.x(), -wi.y(), wi.z()), Vec3(wo.x(), -wo.y(), wo.z()));
    CHECK((h - f).abs().maxCoeff() <= 1e-9 * (1 + f.maxCoeff()));
  }
  CHECK((b->eval(Vec3(0, 0, 1), Vec3(0.6, 0, -0.8)) == 0.0).all());
  CHECK((b->eval(Vec3(0.6, 0, -0.8), Vec3(0, 0, 1)) == 0.0).all());
}

TEST_CASE("measured: interpolation is continuous and tracks a smooth function") {
  // Samples of g(p) = 1 + p.x + 2 p.y + 0.5 p.z in Marschner space on the
  // Cornell angle set; the interpolant must be close to g between samples.
  const SampleSet cay = measured_samples(*Catalogue::builtin().make("cayman"));
  SampleSet s;
  auto g = [](const Vec3& wi, const Vec3& wo) {
    const Vec3 p = marschner_point(wi, wo);
    return 1.0 + p.x() + 2.0 * p.y() + 0.5 * p.z();
  };
  for (size_t k = 0; k < cay.size(); ++k)
    s.push(cay.wi[k], cay.wo[k], Rgb::Constant(g(cay.wi[k], cay.wo[k])));
  s.validate();
  MeasuredOptions nn;
  nn.neighbours = 1;
  const MeasuredBrdf m("test", s, MeasuredOptions{}), nearest("nearest", s, nn);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  double worst = 0.0, mean = 0.0, mean_nn = 0.0;
  const int n = 300;
  for (int k = 0; k < n; ++k) {
    // Inside the measured range: theta up to 75 degrees.
    const Vec3 wi = from_spherical(deg(75) * U(rng), 0.0);
    const Vec3 wo = from_spherical(deg(75) * U(rng), M_PI * (2 * U(rng) - 1));
    const double e = std::abs(m.eval(wi, wo)[0] - g(wi, wo));
    worst = std::max(worst, e);
    mean += e / n;
    mean_nn += std::abs(nearest.eval(wi, wo)[0] - g(wi, wo)) / n;
    // Continuity: a tiny move changes the value a little.
    const Vec3 wo2 = from_spherical(std::acos(wo.z()) + 1e-7, std::atan2(wo.y(), wo.x()));
    CHECK(std::abs(m.eval(wi, wo2)[0] - m.eval(wi, wo)[0]) < 1e-4);
  }
  // The Cornell set is sparse (1439 points in 3D; incident angles 10..80 deg
  // in 10 deg steps), so the error is set by the data: about 1.6% of the
  // function's range of 3 on average, and up to 0.29 for the nearest sample
  // alone. The interpolant must beat nearest-neighbour on average.
  INFO("mean abs error " << mean << " (nearest sample: " << mean_nn << "), worst " << worst);
  CHECK(mean < 0.06);
  CHECK(mean < mean_nn);
  CHECK(worst < 0.3);
}

TEST_CASE("measured: masked samples are kept in samples() but never interpolated") {
  const BrdfPtr b = Catalogue::builtin().make(bad("astm_negative_value.astm"));
  const SampleSet s = measured_samples(*b);
  REQUIRE(s.size() == 2);
  CHECK(s.valid_count() == 1);
  CHECK(s.invalid_value == 1);
  // Only the valid sample remains: eval is its value everywhere above the horizon.
  const Rgb f = b->eval(from_spherical(0.7, 0.0), from_spherical(0.43, -0.26));
  CHECK(f.isApprox(s.value[0]));
  // With band=400 the negative 550 nm value does not matter.
  CHECK(measured_samples(*Catalogue::builtin().make(bad("astm_negative_value.astm") + ":band=400"))
            .valid_count() == 2);
  CHECK_THROWS_WITH(MeasuredBrdf("x", SampleSet{}, MeasuredOptions{}),
                    Contains("expected at least one valid sample, found none"));
}

// ---------------------------------------------------------------- failure kinds

TEST_CASE("astm: every failure kind gives path:line, expected and found") {
  struct Case {
    const char* file;
    const char* message;
  };
  const Case cases[] = {
      {"astm_no_vars.astm", "expected a header line 'KEY value' or 'VARS ...' before the data"},
      {"astm_bad_vars.astm", "astm_bad_vars.astm:4: VARS column 5 expected '400nm', found '380nm'"},
      {"astm_short_row.astm",
       "astm_short_row.astm:7: expected 35 comma-separated values (4 angles, "
       "31 bands), found 20"},
      {"astm_nan.astm", "astm_nan.astm:7: column 20 (550nm) expected a finite number, found 'nan'"},
      {"astm_inf.astm", "astm_inf.astm:7: column 8 (430nm) expected a finite number, found 'inf'"},
      {"astm_not_number.astm",
       "astm_not_number.astm:7: column 12 (470nm) expected a number, found "
       "'0.1.2'"},
      {"astm_degrees.astm",
       "astm_degrees.astm:7: theta_i expected radians in [0, pi/2], found 45 "
       "(degrees?"},
      {"astm_phi_range.astm",
       "astm_phi_range.astm:7: phi_s expected radians in [-2pi, 2pi], found "
       "12.5"},
      {"astm_count_mismatch.astm", "NUM_POINTS expected 3 data rows, found 2 (truncated file?)"},
      {"astm_huge_num_points.astm",
       "astm_huge_num_points.astm:3: NUM_POINTS expected an integer in "
       "1..10000000, found '99999999999'"},
      {"astm_no_rows.astm", "expected data rows after VARS, found none"},
      {"astm_bad_header_line.astm",
       "astm_bad_header_line.astm:3: expected a header line 'KEY value'"},
  };
  for (const Case& c : cases) {
    INFO(c.file);
    CHECK_THROWS_AS(read_astm(bad(c.file)), std::invalid_argument);
    CHECK_THROWS_WITH(read_astm(bad(c.file)), Contains(c.message));
    // The same error through the catalogue.
    CHECK_THROWS_WITH(Catalogue::builtin().make(bad(c.file)), Contains(c.message));
  }
  CHECK_THROWS_WITH(Catalogue::builtin().make(bad("missing.astm")), Contains("file not found"));
}

TEST_CASE("astm: absurd lines and files are rejected without reading them whole") {
  TempDir d("astm");
  {
    std::ofstream f(d.file("long.astm"));
    f << "SAMPLE_NAME " << std::string(200000, 'x') << "\n";
  }
  CHECK_THROWS_WITH(read_astm(d.file("long.astm")),
                    Contains("long.astm:1: expected a line of at most 65536 characters"));
  {
    std::ofstream f(d.file("binary.astm"), std::ios::binary);
    for (int k = 0; k < 1000; ++k)
      f.put(static_cast<char>(k * 37 % 256 == '\n' ? 1 : k * 37 % 256));
  }
  CHECK_THROWS_AS(read_astm(d.file("binary.astm")), std::invalid_argument);
  { std::ofstream f(d.file("empty.astm")); }
  CHECK_THROWS_WITH(read_astm(d.file("empty.astm")), Contains("expected a line 'VARS theta_i"));
}

TEST_CASE("brdf: every failure kind gives path:line, expected and found") {
  struct Case {
    const char* file;
    const char* message;
  };
  const Case cases[] = {
      {"brdf_truncated.brdf",
       "brdf_truncated.brdf:9: record 2 expected 35 numbers (4 angles, 31 "
       "values), found 17 before the end of file (truncated file?)"},
      {"brdf_nwl.brdf",
       "brdf_nwl.brdf:2: expected 31 wavelengths (400..700 nm in 10 nm steps), "
       "found '1000000000'"},
      {"brdf_bad_wavelength.brdf",
       "brdf_bad_wavelength.brdf:5: wavelength 4 expected 430 nm, "
       "found '435'"},
      {"brdf_nan.brdf", "brdf_nan.brdf:9: record 2 600nm expected a finite number, found 'nan'"},
      {"brdf_token.brdf", "brdf_token.brdf:9: record 2 420nm expected a number, found '0.5x'"},
      {"brdf_degrees.brdf",
       "brdf_degrees.brdf:9: theta_i expected radians in [0, pi/2], found 40 "
       "(degrees?"},
      {"brdf_no_records.brdf", "expected at least one record after the wavelengths, found none"},
      {"brdf_empty.brdf", "expected the number of wavelengths (31), found end of file"},
      {"brdf_wl_eof.brdf", "expected 31 wavelengths, found 4 before the end of file"},
  };
  for (const Case& c : cases) {
    INFO(c.file);
    CHECK_THROWS_AS(read_pbrt_brdf(bad(c.file)), std::invalid_argument);
    CHECK_THROWS_WITH(read_pbrt_brdf(bad(c.file)), Contains(c.message));
  }
}

TEST_CASE("cli: a bad measured file exits 2 with one line and writes nothing") {
  TempDir d("cli_measured");
  const std::string out = d.file("s.csv");
  std::string err;
  CHECK(run_cli_stderr("sample --brdf " + bad("astm_nan.astm") + " --grid 4 --out " + out, &err) == 2);
  CHECK_THAT(err, Contains("brdf-factor: ") && Contains("astm_nan.astm:7: column 20 (550nm)"));
  CHECK(std::count(err.begin(), err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(out));
  CHECK(run_cli_stderr("eval --brdf " + bad("brdf_truncated.brdf") + " --wi 0,0,1 --wo 0,0,1", &err) == 2);
  CHECK_THAT(err, Contains("truncated file?"));
  CHECK(run_cli_stderr("eval --brdf cayman:band=550 --wi 0,0,1 --wo 0,0,1", &err) == 0);
}

TEST_CASE("spectral: the gamut mapping keeps every channel at the floor fraction of the luminance") {
  const Eigen::Vector3d w = rgb_luminance_weights();
  REQUIRE(kGamutFloor > 0.0);
  // Out of gamut: the smallest channel lands on floor x Y, Y kept.
  Rgb v(-0.1, 0.3, 0.9);
  const double y = w.dot(v.matrix());
  CHECK(desaturate_into_gamut(v, w, kGamutFloor));
  CHECK(v.minCoeff() == Approx(kGamutFloor * y).epsilon(1e-12));
  CHECK(w.dot(v.matrix()) == Approx(y).epsilon(1e-12));
  // In gamut but with a channel below the floor (a desaturated residue): lifted.
  Rgb tiny(1e-19, 0.3, 0.9);
  CHECK(desaturate_into_gamut(tiny, w, kGamutFloor));
  CHECK(tiny.minCoeff() == Approx(kGamutFloor * w.dot(Rgb(1e-19, 0.3, 0.9).matrix())).epsilon(1e-12));
  // Above the floor: unchanged.
  Rgb fine(0.2, 0.3, 0.4);
  CHECK_FALSE(desaturate_into_gamut(fine, w, kGamutFloor));
  CHECK(fine.isApprox(Rgb(0.2, 0.3, 0.4)));
}

TEST_CASE("spectral: no Cornell channel is an exact zero - none reads as ln(eps) in the metrics") {
  // krylon-blue had one channel at exactly 0 in 919 of its 1,439 samples (the
  // gamut mapping stopped at 0), which the log metrics read as ln(eps). With
  // gamut_floor = 0 (the old mapping) this test fails: zeros = 919 on krylon.
  const Eigen::Vector3d w = rgb_luminance_weights();
  for (const char* name : {"krylon-blue", "cayman", "acryl-blue", "mystique", "garnet-red"}) {
    INFO(name);
    const SampleSet s = measured_samples(*Catalogue::builtin().make(name));
    // The metrics' log transform (factor/metrics.h): g = ln((f + eps A) / A), A the channel mean.
    const double eps = 1e-5;
    Rgb a = Rgb::Zero();
    for (size_t k = 0; k < s.size(); ++k)
      if (s.valid[k]) a += s.value[k] / double(s.valid_count());
    size_t zeros = 0, at_eps = 0;
    for (size_t k = 0; k < s.size(); ++k) {
      if (!s.valid[k]) continue;
      const double y = w.dot(s.value[k].matrix());
      if (!(y > 0)) continue;  // a black sample (every band 0) is black in every channel
      for (int c = 0; c < 3; ++c) {
        zeros += s.value[k][c] == 0.0;
        // In the log metrics, no channel lies more than ln(1 / floor) below the sample's luminance
        // (a zero channel read as ln(eps), 11.5 below A and far further below its sample).
        at_eps += std::log((s.value[k][c] + eps * a[c]) / a[c]) <
                  std::log((kGamutFloor * y + eps * a[c]) / a[c]) - 1e-9;
        CHECK(s.value[k][c] >= kGamutFloor * y * (1 - 1e-9));
      }
    }
    CHECK(zeros == 0);
    CHECK(at_eps == 0);
    CHECK(s.description.find("kept at >= 1% of the luminance") != std::string::npos);
  }
}

TEST_CASE("spectral: gamut_floor = 0 is the old mapping to the gamut's edge - and a bad floor is refused") {
  const SampleSet edge = measured_samples(*Catalogue::builtin().make("krylon-blue:gamut_floor=0"));
  const Eigen::Vector3d w = rgb_luminance_weights();
  size_t zeros = 0;
  for (size_t k = 0; k < edge.size(); ++k)
    if (edge.valid[k] && w.dot(edge.value[k].matrix()) > 0 && edge.value[k].minCoeff() == 0.0) ++zeros;
  CHECK(zeros > 900);  // measured: 919 samples with one channel at exactly 0
  CHECK_THROWS_WITH(Catalogue::builtin().make("krylon-blue:gamut_floor=0.7"),
                    Catch::Contains("gamut_floor") && Catch::Contains("0..0.5") && Catch::Contains("0.7"));
}
