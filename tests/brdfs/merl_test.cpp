// Tests of the MERL .binary reader/writer, the MERL half/difference angles,
// MerlBrdf's lookups and sample builder, corrupt files (built in a temp dir),
// and the export-merl subcommand.
#include "brdfs/merl.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "brdfs/catalogue.h"
#include "brdfs/directions.h"
#include "brdfs/measured.h"
#include "brdfs/models.h"
#include "test_common.h"

using namespace bf;
using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;

using bf_test::slurp;
using bf_test::TempDir;

using bf_test::run_cli_stderr;

// A MERL-like file with the given header and `doubles` payload values (all
// `fill`, little-endian on the little-endian hosts we build on).
void write_raw(const std::string& path, int32_t d0, int32_t d1, int32_t d2, size_t doubles,
               double fill = 0.5) {
  std::ofstream f(path, std::ios::binary);
  const int32_t dims[3] = {d0, d1, d2};
  f.write(reinterpret_cast<const char*>(dims), sizeof dims);
  const std::vector<double> v(doubles, fill);
  f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(v.size() * 8));
}

// A smooth isotropic, reciprocal test BRDF: different in each channel and
// varying along all three MERL axes.
class SmoothBrdf final : public Brdf {
 public:
  Rgb eval(const Vec3& wi, const Vec3& wo) const override {
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return Rgb::Zero();
    const MerlAngles a = merl_half_diff(wi, wo);
    return Rgb(0.2 + std::exp(-10.0 * a.theta_h), 0.3 + 0.5 * std::cos(a.theta_d),
               0.4 + 0.2 * std::cos(2.0 * a.phi_d));
  }
  std::string name() const override { return "smooth"; }
  std::string to_string() const override { return "smooth"; }
};

double merl_deg(double d) {
  return d * M_PI / 180.0;
}

}  // namespace

TEST_CASE("merl: half/diff angles in known configurations") {
  // wi = wo: h = wi, theta_d = 0.
  for (double th : {0.0, 0.3, 1.2}) {
    const Vec3 w = from_spherical(th, 0.7);
    const MerlAngles a = merl_half_diff(w, w);
    CHECK(a.theta_h == Approx(th).margin(1e-12));
    CHECK(a.theta_d == Approx(0.0).margin(1e-7));
  }
  // Mirror pairs: h = n, theta_d = theta_i, phi_d = phi_i.
  for (double phi : {0.0, 0.4, 2.0, -1.0}) {
    const MerlAngles a = merl_half_diff(from_spherical(0.6, phi), from_spherical(0.6, phi + M_PI));
    CHECK(a.theta_h == Approx(0.0).margin(1e-12));
    CHECK(a.theta_d == Approx(0.6).margin(1e-12));
    CHECK(a.phi_d == Approx(phi).margin(1e-12));
  }
  // Agreement with directions.h on the frame-independent quantities, the
  // inverse, and reciprocity (swap -> phi_d + pi).
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 1000; ++k) {
    const Vec3 wi = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const Vec3 wo = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const MerlAngles a = merl_half_diff(wi, wo);
    Vec3 h, d;
    half_diff(wi, wo, h, d);
    INFO("wi=" << wi.transpose() << " wo=" << wo.transpose());
    CHECK(a.theta_h == Approx(std::acos(h.z())).margin(1e-7));
    CHECK(a.theta_d == Approx(std::acos(std::clamp(d.z(), -1.0, 1.0))).margin(1e-7));
    CHECK(a.theta_h <= M_PI / 2);
    CHECK(a.theta_d <= M_PI / 2 + 1e-12);
    const MerlAngles b = merl_half_diff(wo, wi);
    CHECK(b.theta_h == Approx(a.theta_h).margin(1e-12));
    CHECK(b.theta_d == Approx(a.theta_d).margin(1e-12));
    CHECK(std::remainder(b.phi_d - a.phi_d - M_PI, 2 * M_PI) == Approx(0.0).margin(1e-9));
    // The inverse gives the pair rotated about n by -phi_h.
    Vec3 i2, o2;
    merl_half_diff_inverse(a, i2, o2);
    const Vec3 hh = (wi + wo).normalized();
    const Eigen::AngleAxisd rot(-std::atan2(hh.y(), hh.x()), Vec3::UnitZ());
    CHECK((i2 - rot * wi).norm() < 1e-9);
    CHECK((o2 - rot * wo).norm() < 1e-9);
  }
}

TEST_CASE("merl: bin indices follow the reference, centres map to their bins") {
  CHECK(merl_theta_h_index(0.0) == 0);
  CHECK(merl_theta_h_index(-1.0) == 0);
  CHECK(merl_theta_h_index(M_PI / 2) == 89);
  // Non-linear theta_h: bin 1 starts at (1/90)^2 * 90 deg = 0.0111 deg.
  CHECK(merl_theta_h_index(merl_deg(0.0110)) == 0);
  CHECK(merl_theta_h_index(merl_deg(0.0112)) == 1);
  CHECK(merl_theta_h_index(merl_deg(22.5)) == 45);  // sqrt(1/4) * 90
  CHECK(merl_theta_d_index(merl_deg(45.5)) == 45);
  CHECK(merl_theta_d_index(M_PI) == 89);
  CHECK(merl_phi_d_index(merl_deg(10.2)) == 10);
  CHECK(merl_phi_d_index(merl_deg(10.2) - M_PI) == 10);  // folded by pi
  CHECK(merl_phi_d_index(M_PI) == 0);               // pi == 0 after folding
  CHECK(merl_phi_d_index(std::nan("")) == 0);
  for (int i = 0; i < 90; ++i) {
    CHECK(merl_theta_h_index(merl_theta_h_centre(i)) == i);
    CHECK(merl_theta_d_index(merl_theta_d_centre(i)) == i);
  }
  for (int k = 0; k < 180; ++k) CHECK(merl_phi_d_index(merl_phi_d_centre(k)) == k);
  CHECK(merl_cell(89, 89, 179) == kMerlCells - 1);
  CHECK(kMerlFileBytes == 34992012u);
}

TEST_CASE("merl: write then read reproduces an analytic BRDF at bin centres") {
  TempDir d("merl_rt");
  for (int which = 0; which < 2; ++which) {
    LambertParams lp;
    lp.kd = Rgb(0.2, 0.5, 0.8);
    const Lambert lambert(lp);
    const SmoothBrdf smooth;
    const Brdf& brdf = which == 0 ? static_cast<const Brdf&>(lambert) : smooth;
    INFO(brdf.to_string());
    MerlTabulateStats st;
    const MerlTable t = merl_tabulate(brdf, &st);
    CHECK(st.cells == kMerlCells);
    CHECK(st.invalid == 0);
    CHECK(st.below_horizon > 0);
    CHECK(t.missing_count() == st.below_horizon);
    const std::string path = d.file("rt.binary");
    write_merl(t, path);
    CHECK(fs::file_size(path) == kMerlFileBytes);
    CHECK_FALSE(fs::exists(path + ".tmp"));
    const MerlTable r = read_merl(path);
    REQUIRE(r.raw.size() == t.raw.size());
    CHECK(std::memcmp(r.raw.data(), t.raw.data(), r.raw.size() * 8) == 0);
    for (MerlLookup lookup : {MerlLookup::Nearest, MerlLookup::Linear}) {
      const MerlBrdf m(std::make_shared<const MerlTable>(r), lookup, path);
      size_t checked = 0;
      for (int h = 0; h < 90; h += 7)
        for (int dd = 0; dd < 90; dd += 5)
          for (int p = 0; p < 180; p += 11) {
            Vec3 wi, wo;
            merl_half_diff_inverse(
                {merl_theta_h_centre(h), merl_theta_d_centre(dd), merl_phi_d_centre(p)}, wi, wo);
            if (wi.z() <= 0.0 || wo.z() <= 0.0) continue;
            // Nearest: the stored double, so float precision. Linear at a
            // centre: the centre's weight is 1 up to rounding of the angles.
            const Rgb want = brdf.eval(wi, wo);
            const Rgb got = m.eval(wi, wo);
            INFO("bin " << h << " " << dd << " " << p << " want " << want.transpose() << " got "
                        << got.transpose());
            const double tol = lookup == MerlLookup::Nearest ? 1e-14 : 1e-10;
            CHECK(((got - want).abs() <= tol * (1.0 + want.abs())).all());
            ++checked;
          }
      CHECK(checked > 1000);
    }
  }
}

TEST_CASE("merl: nearest lookup matches the reference indexing and linear is trilinear") {
  // A table whose value is a known linear function of the three bin indices.
  auto t = std::make_shared<MerlTable>();
  t->raw.resize(3 * kMerlCells);
  for (int h = 0; h < 90; ++h)
    for (int d = 0; d < 90; ++d)
      for (int p = 0; p < 180; ++p) {
        const size_t c = merl_cell(h, d, p);
        t->raw[c] = 1.0 + h;
        t->raw[kMerlCells + c] = 1.0 + d;
        t->raw[2 * kMerlCells + c] = 1.0 + p;
      }
  const MerlBrdf nearest(t, MerlLookup::Nearest, "indices");
  const MerlBrdf linear(t, MerlLookup::Linear, "indices");
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 500; ++k) {
    const Vec3 wi = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const Vec3 wo = from_spherical(std::acos(U(rng)), 2 * M_PI * U(rng));
    const MerlAngles a = merl_half_diff(wi, wo);
    const Rgb f = nearest.eval(wi, wo);
    CHECK(f[0] == Approx((1.0 + merl_theta_h_index(a.theta_h)) * kMerlScale[0]));
    CHECK(f[1] == Approx((1.0 + merl_theta_d_index(a.theta_d)) * kMerlScale[1]));
    CHECK(f[2] == Approx((1.0 + merl_phi_d_index(a.phi_d)) * kMerlScale[2]));
  }
  // Linear: at fractional index coordinates (u, v, w) inside the grid the
  // result is 1 + u, 1 + v, 1 + w (times the scales).
  for (int k = 0; k < 200; ++k) {
    const double u = 1 + 87 * U(rng), v = 1 + 87 * U(rng), w = 1 + 177 * U(rng);
    const double th = std::pow((u + 0.5) / 90, 2) * M_PI / 2;
    Vec3 wi, wo;
    merl_half_diff_inverse({th, (v + 0.5) / 90 * M_PI / 2, (w + 0.5) / 180 * M_PI}, wi, wo);
    if (wi.z() <= 0.0 || wo.z() <= 0.0) continue;
    const Rgb f = linear.eval(wi, wo);
    CHECK(f[0] / kMerlScale[0] == Approx(1 + u).epsilon(1e-9));
    CHECK(f[1] / kMerlScale[1] == Approx(1 + v).epsilon(1e-9));
    CHECK(f[2] / kMerlScale[2] == Approx(1 + w).epsilon(1e-9));
  }
  // phi_d is periodic: between the last and the first bin the blue channel
  // blends bins 179 and 0.
  Vec3 wi, wo;
  merl_half_diff_inverse({merl_theta_h_centre(40), merl_theta_d_centre(20), M_PI - 1e-9}, wi, wo);
  CHECK(linear.eval(wi, wo)[2] / kMerlScale[2] == Approx(0.5 * (180 + 1)).epsilon(1e-6));
}

TEST_CASE("merl: missing cells give 0, are renormalized away, and are masked in samples") {
  auto t = std::make_shared<MerlTable>(merl_tabulate(Lambert(LambertParams{})));
  // Mark one above-horizon cell missing (negative in one channel only).
  const int h = 30, d = 30, p = 60;
  const size_t cell = merl_cell(h, d, p);
  REQUIRE_FALSE(t->missing(cell));
  t->raw[kMerlCells + cell] = -1.0;
  const size_t missing = t->missing_count();
  const MerlBrdf nearest(t, MerlLookup::Nearest, "holes");
  const MerlBrdf linear(t, MerlLookup::Linear, "holes");
  Vec3 wi, wo;
  merl_half_diff_inverse({merl_theta_h_centre(h), merl_theta_d_centre(d), merl_phi_d_centre(p)}, wi,
                         wo);
  CHECK((nearest.eval(wi, wo) == 0.0).all());
  // Linear: the 7 valid corners around the hole still give the Lambert value.
  merl_half_diff_inverse(
      {merl_theta_h_centre(h) + 1e-4, merl_theta_d_centre(d) + 1e-3, merl_phi_d_centre(p) + 1e-3},
      wi, wo);
  CHECK(linear.eval(wi, wo).isApprox(Rgb::Constant(0.5 / M_PI), 1e-12));
  // samples(): the hole and every below-horizon centre are masked, never fed to fits.
  const SampleSet s = linear.samples(1);
  CHECK(s.size() == kMerlCells);
  CHECK(s.valid_count() == kMerlCells - missing);
  for (size_t k = 0; k < s.size(); k += 997)
    if (s.valid[k]) CHECK(s.value[k].isApprox(Rgb::Constant(0.5 / M_PI), 1e-14));
  const SampleSet s3 = measured_samples(linear);
  CHECK(s3.size() == kMerlCells);
  CHECK(linear.samples(10).size() == 9u * 9u * 18u);
  CHECK_THROWS_WITH(linear.samples(0), Contains("stride expected 1..90, found 0"));
  // Below the horizon eval is 0 whatever the table says.
  CHECK((linear.eval(Vec3(0, 0, 1), Vec3(0.6, 0, -0.8)) == 0.0).all());
}

TEST_CASE("merl: defined_at is false exactly where eval has no table value to return") {
  auto t = std::make_shared<MerlTable>(merl_tabulate(Lambert(LambertParams{})));
  const int h = 30, d = 30, p = 60;
  t->raw[merl_cell(h, d, p)] = -1.0;
  const MerlBrdf nearest(t, MerlLookup::Nearest, "hole");
  const MerlBrdf linear(t, MerlLookup::Linear, "hole");
  Vec3 wi, wo;
  merl_half_diff_inverse({merl_theta_h_centre(h), merl_theta_d_centre(d), merl_phi_d_centre(p)}, wi, wo);
  CHECK_FALSE(nearest.defined_at(wi, wo));
  merl_half_diff_inverse(
      {merl_theta_h_centre(h) + 1e-4, merl_theta_d_centre(d) + 1e-3, merl_phi_d_centre(p) + 1e-3}, wi, wo);
  CHECK(linear.defined_at(wi, wo));  // its 7 other corners hold values
  merl_half_diff_inverse({merl_theta_h_centre(h), merl_theta_d_centre(d), merl_phi_d_centre(p + 1)}, wi, wo);
  CHECK(nearest.defined_at(wi, wo));
  // All 8 corners of a linear lookup missing: no value.
  for (int dh = 0; dh < 2; ++dh)
    for (int dd = 0; dd < 2; ++dd)
      for (int dp = 0; dp < 2; ++dp) t->raw[merl_cell(h + dh, d + dd, p + dp)] = -1.0;
  merl_half_diff_inverse(
      {0.5 * (merl_theta_h_centre(h) + merl_theta_h_centre(h + 1)), merl_theta_d_centre(d) + 0.004,
       merl_phi_d_centre(p) + 0.008},
      wi, wo);
  CHECK_FALSE(linear.defined_at(wi, wo));
  CHECK((linear.eval(wi, wo) == 0.0).all());
  // Below the horizon the BRDF is 0 by definition: defined.
  CHECK(linear.defined_at(Vec3(0, 0, 1), Vec3(0.6, 0, -0.8)));
}

TEST_CASE("merl: corrupt files are rejected with expected and found") {
  TempDir d("merl_bad");
  const size_t n = 3 * kMerlCells;
  struct Case {
    std::string name;
    std::function<void(const std::string&)> make;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"empty.binary", [](const std::string& p) { std::ofstream f(p); },
       "merl: expected a 12-byte header (three int32 dims), file has 0 bytes"},
      {"short_header.binary",
       [](const std::string& p) { std::ofstream(p, std::ios::binary) << "abcde"; },
       "file has 5 bytes"},
      {"truncated.binary", [n](const std::string& p) { write_raw(p, 90, 90, 180, n - 1000); },
       "merl: expected 90*90*180*3 = 4374000 doubles (34992012 bytes with the header), file has "
       "4373000 doubles (34984012 bytes) (truncated?)"},
      {"header_only.binary", [](const std::string& p) { write_raw(p, 90, 90, 180, 0); },
       "file has 0 doubles (12 bytes)"},
      {"too_long.binary", [n](const std::string& p) { write_raw(p, 90, 90, 180, n + 1); },
       "file has 4374001 doubles"},
      {"wrong_dims.binary", [](const std::string& p) { write_raw(p, 90, 90, 90, 16); },
       "merl: expected dims 90 90 180, found 90 90 90 (dims[2] should be 180)"},
      {"swapped_dims.binary", [](const std::string& p) { write_raw(p, 180, 90, 90, 16); },
       "found 180 90 90 (dims[0] should be 90)"},
      // Dims are checked before the size, so these need no payload. Product
      // 1458000, but negative: rejected per dimension.
      {"negative_dims.binary", [](const std::string& p) { write_raw(p, -90, -90, 180, 16); },
       "found -90 -90 180 (dims[0] should be 90)"},
      {"huge_dims.binary", [](const std::string& p) { write_raw(p, 90, 90, 1 << 30, 16); },
       "found 90 90 1073741824 (dims[2] should be 180)"},
      {"nan.binary",
       [n](const std::string& p) {
         write_raw(p, 90, 90, 180, n);
         std::fstream f(p, std::ios::binary | std::ios::in | std::ios::out);
         const double nan = std::nan("");
         f.seekp(12 + 8 * (kMerlCells + merl_cell(3, 4, 5)));
         f.write(reinterpret_cast<const char*>(&nan), 8);
       },
       "merl: expected finite values, found nan in the green block at theta_h bin 3, theta_d bin "
       "4, phi_d bin 5"},
      {"inf.binary",
       [n](const std::string& p) {
         write_raw(p, 90, 90, 180, n);
         std::fstream f(p, std::ios::binary | std::ios::in | std::ios::out);
         const double inf = -HUGE_VAL;
         f.seekp(12 + 8 * (2 * kMerlCells + kMerlCells - 1));
         f.write(reinterpret_cast<const char*>(&inf), 8);
       },
       "found -inf in the blue block at theta_h bin 89, theta_d bin 89, phi_d bin 179"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const std::string p = d.file(c.name);
    c.make(p);
    CHECK_THROWS_AS(read_merl(p), std::invalid_argument);
    CHECK_THROWS_WITH(read_merl(p), Contains(c.message) && Contains(p));
    CHECK_THROWS_WITH(Catalogue::builtin().make(p), Contains(c.message));
  }
  CHECK_THROWS_WITH(read_merl(d.path.string()), Contains("expected a regular file"));
  CHECK_THROWS_WITH(read_merl(d.file("absent.binary")), Contains("found nothing"));
  // The writer refuses tables of the wrong size or with NaN, and leaves nothing.
  MerlTable small;
  small.raw.assign(10, 0.0);
  CHECK_THROWS_WITH(write_merl(small, d.file("w.binary")),
                    Contains("expected a table of 4374000 doubles, found 10"));
  MerlTable nan = merl_tabulate(Lambert(LambertParams{}));
  nan.raw[5] = std::nan("");
  CHECK_THROWS_WITH(write_merl(nan, d.file("w.binary")), Contains("non-finite value in the red"));
  CHECK_FALSE(fs::exists(d.file("w.binary")));
  CHECK_FALSE(fs::exists(d.file("w.binary.tmp")));
}

TEST_CASE("merl: loader options and tabulating invalid values") {
  TempDir d("merl_opt");
  const std::string p = d.file("lambert.binary");
  write_merl(merl_tabulate(Lambert(LambertParams{})), p);
  const Catalogue& cat = Catalogue::builtin();
  CHECK(cat.make(p)->to_string().find("lookup=nearest") != std::string::npos);
  CHECK(cat.make(p + ":lookup=linear")->to_string().find("lookup=linear") != std::string::npos);
  CHECK_THROWS_WITH(cat.make(p + ":lookup=cubic"),
                    Contains("lookup expected 'nearest' or 'linear', found 'cubic'"));
  CHECK_THROWS_WITH(cat.make(p + ":band=550"), Contains("unknown parameter 'band'"));
  // A BRDF returning NaN or negative values: those cells are written as missing.
  class Broken final : public Brdf {
   public:
    Rgb eval(const Vec3& wi, const Vec3&) const override {
      if (wi.x() > 0.5) return Rgb::Constant(std::nan(""));
      if (wi.x() < -0.5) return Rgb(-1.0, 0.1, 0.1);
      return Rgb::Constant(0.1);
    }
    std::string name() const override { return "broken"; }
    std::string to_string() const override { return "broken"; }
  };
  MerlTabulateStats st;
  const MerlTable t = merl_tabulate(Broken(), &st);
  CHECK(st.invalid > 0);
  CHECK(t.missing_count() == st.invalid + st.below_horizon);
  for (double v : t.raw) REQUIRE(std::isfinite(v));
}

TEST_CASE("cli: export-merl writes a readable 34,992,012-byte file, atomically") {
  TempDir d("cli_merl");
  const std::string out = d.file("lambert.binary");
  std::string err;
  REQUIRE(run_cli_stderr("export-merl --brdf lambert:kd=0.3 --out " + out, &err) == 0);
  CHECK(fs::file_size(out) == kMerlFileBytes);
  CHECK_FALSE(fs::exists(out + ".tmp"));
  const BrdfPtr b = Catalogue::builtin().make(out);
  CHECK(b->eval(from_spherical(0.3, 0.0), from_spherical(0.5, 2.0))
            .isApprox(Rgb::Constant(0.3 / M_PI), 1e-14));
  // Failures exit 2, write nothing, and leave an existing file untouched.
  const std::string missing = d.file("nothing.binary");
  CHECK(run_cli_stderr("export-merl --brdf nope --out " + missing, &err) == 2);
  CHECK_THAT(err, Contains("brdf-factor: --brdf: unknown BRDF 'nope'"));
  CHECK_FALSE(fs::exists(missing));
  // Every MERL file has the same size: compare the bytes, not the size.
  const std::string before = slurp(out);
  REQUIRE(before.size() == kMerlFileBytes);
  CHECK(run_cli_stderr("export-merl --brdf " + std::string(BF_TEST_DATA_DIR) +
                    "/measured/astm_degrees.astm --out " + out,
                &err) == 2);
  CHECK_THAT(err, Contains("(degrees?"));
  CHECK(slurp(out) == before);
  // A successful export of another BRDF does change the bytes (the comparison
  // can fail), through a rename that leaves no temporary behind.
  REQUIRE(run_cli_stderr("export-merl --brdf lambert:kd=0.5 --out " + out, &err) == 0);
  CHECK(slurp(out) != before);
  size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(d.path)) ++entries;
  CHECK(entries == 1);  // no temporary left beside it
  CHECK(run_cli_stderr("export-merl --brdf lambert --out " + d.file("no/such/dir/x.binary"), &err) == 2);
  CHECK_THAT(err, Contains("cannot open"));
}

TEST_CASE("merl: cell measure weights make cell averages uniform averages over the hemisphere pair") {
  // Over pairs uniform in solid angle, E[cos theta_o] = 1/2 and E[cos theta_i cos theta_o] = 1/4.
  auto t = std::make_shared<MerlTable>(merl_tabulate(Lambert(LambertParams{})));
  const MerlBrdf table(t, MerlLookup::Nearest, "lambert");
  const SampleSet w = table.samples(1, true);
  const SampleSet u = table.samples(1, false);
  REQUIRE(w.weight.size() == w.size());
  CHECK(u.weight.empty());
  CHECK_THAT(w.description, Contains("weighted by cell measure"));
  double sw = 0, m1 = 0, m2 = 0, su = 0, u1 = 0;
  for (size_t k = 0; k < w.size(); ++k) {
    if (!w.valid[k]) continue;
    sw += w.weight[k];
    m1 += w.weight[k] * w.wo[k].z();
    m2 += w.weight[k] * w.wi[k].z() * w.wo[k].z();
    su += 1;
    u1 += u.wo[k].z();
  }
  CHECK(sw / su == Approx(1.0).epsilon(1e-12));  // normalized to mean 1 over the valid cells
  CHECK(m1 / sw == Approx(0.5).margin(0.01));
  CHECK(m2 / sw == Approx(0.25).margin(0.01));
  CHECK(std::abs(u1 / su - 0.5) > 0.03);  // unweighted cells are not uniform in the pair measure
  // The closed form of one cell: sin(theta_h) dtheta_h sin(theta_d) cos(theta_d) dtheta_d dphi_d.
  const double th = merl_theta_h_centre(10), td = merl_theta_d_centre(20);
  const double dth = (std::pow(11.0 / 90, 2) - std::pow(10.0 / 90, 2)) * M_PI / 2;
  CHECK(merl_cell_measure(10, 20) ==
        Approx(std::sin(th) * dth * std::sin(td) * std::cos(td) * (M_PI / 180) * (M_PI / 180)).epsilon(1e-12));
}
