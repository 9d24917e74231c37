// Angles beyond pi/2 (below the horizon) in every reader that reads angles
// (docs/robustness.md "Reader angle bounds"):
//   - Cornell ASTM and pbrt .brdf: a measured direction is above the surface,
//     so theta beyond pi/2 (+1e-6) is an error naming path:line and the field;
//     within that tolerance the record is read and masked as below the horizon.
//   - sample-list CSV: theta in [0, pi] (the writer stores masked samples as
//     theta = pi); theta in (pi/2, pi] is masked and counted as below the
//     horizon, never used; outside [0, pi] is an error naming path:line and field.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "brdfs/measured.h"
#include "brdfs/sample_csv.h"
#include "test_common.h"

using namespace bf;
using Catch::Matchers::Contains;
using bf_test::TempDir;

namespace {

std::string num(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// An ASTM file with one row per angle quadruple (all bands 0.25).
std::string write_astm(const TempDir& d, const std::string& name, const std::vector<std::array<double, 4>>& rows) {
  std::ofstream f(d.file(name));
  f << "SAMPLE_NAME angles\nNUM_POINTS " << rows.size() << "\nVARS theta_i,phi_i,theta_s,phi_s";
  for (int b = 0; b < 31; ++b) f << "," << 400 + 10 * b << "nm";
  f << "\n";
  for (const auto& r : rows) {
    f << num(r[0]) << "," << num(r[1]) << "," << num(r[2]) << "," << num(r[3]);
    for (int b = 0; b < 31; ++b) f << ",0.25";
    f << "\n";
  }
  return d.file(name);
}

// A pbrt .brdf file: 31 wavelengths on line 2, then one record per line from line 3.
std::string write_brdf(const TempDir& d, const std::string& name, const std::vector<std::array<double, 4>>& rows) {
  std::ofstream f(d.file(name));
  f << "31\n";
  for (int b = 0; b < 31; ++b) f << 400 + 10 * b << (b < 30 ? " " : "\n");
  for (const auto& r : rows) {
    f << num(r[0]) << " " << num(r[1]) << " " << num(r[2]) << " " << num(r[3]);
    for (int b = 0; b < 31; ++b) f << " 0.25";
    f << "\n";
  }
  return d.file(name);
}

}  // namespace

TEST_CASE("readers: ASTM and pbrt .brdf reject theta beyond pi/2 naming path, line and field") {
  TempDir d("angles");
  const double below = 1.6;                   // radians: 91.7 degrees, below the horizon
  const std::array<double, 4> ok{0.3, 0.0, 0.4, 3.0};
  struct Case {
    int field;          // 0 theta_i, 2 theta_s
    double value;
    const char* name;
    const char* shown;  // the value as the message prints it (6 significant digits)
  };
  for (const Case c : {Case{0, below, "theta_i", "1.6"}, Case{2, below, "theta_s", "1.6"},
                       Case{0, 3.0, "theta_i", "3"}, Case{2, M_PI, "theta_s", "3.14159"},
                       Case{0, M_PI / 2 + 1e-5, "theta_i", "1.5708"}, Case{2, -0.1, "theta_s", "-0.1"}}) {
    INFO(c.name << " = " << c.value);
    std::array<double, 4> bad = ok;
    bad[c.field] = c.value;
    // ASTM: header lines 1-3, rows from line 4; the bad row is the second.
    const std::string a = write_astm(d, "a.astm", {ok, bad});
    CHECK_THROWS_WITH(read_astm(a), Contains("a.astm:5: " + std::string(c.name) + " expected radians in [0, pi/2], found " +
                                             c.shown));
    // pbrt: records from line 3; the bad record is on line 4.
    const std::string b = write_brdf(d, "b.brdf", {ok, bad});
    CHECK_THROWS_WITH(read_pbrt_brdf(b), Contains("b.brdf:4: " + std::string(c.name) +
                                                  " expected radians in [0, pi/2], found " + c.shown));
  }
  // A value just beyond pi/2 but not a degree reading says so.
  CHECK_THROWS_WITH(read_astm(write_astm(d, "c.astm", {{below, 0.0, 0.4, 3.0}})), Contains("below the horizon"));
}

TEST_CASE("readers: ASTM and pbrt .brdf theta within 1e-6 beyond pi/2 is read, then masked as below the horizon") {
  TempDir d("angles_tol");
  const double over = M_PI / 2 + 5e-7;  // cos = -5e-7
  const std::vector<std::array<double, 4>> rows = {
      {0.3, 0.0, 0.4, 3.0}, {over, 0.0, 0.4, 3.0}, {0.3, 0.0, over, 3.0}, {0.5, 1.0, 0.2, 2.0}};
  for (const SpectralMeasurements& m : {read_astm(write_astm(d, "t.astm", rows)), read_pbrt_brdf(write_brdf(d, "t.brdf", rows))}) {
    INFO(m.path);
    REQUIRE(m.size() == 4);
    const SampleSet s = spectral_to_samples(m, 550);
    CHECK(s.valid_count() == 2);
    CHECK(s.invalid_horizon == 2);
    CHECK(s.valid[0] == 1);
    CHECK(s.valid[1] == 0);
    CHECK(s.valid[2] == 0);
    CHECK(s.valid[3] == 1);
  }
}

TEST_CASE("readers: a sample-list CSV masks and counts theta between pi/2 and pi, rejects theta beyond pi") {
  TempDir d("angles_csv");
  {
    std::ofstream f(d.file("m.csv"));
    f << "theta_i,phi_i,theta_o,phi_o,r,g,b\n"
      << "0.3,0,0.4,3,0.5,0.5,0.5\n"
      << "1.6,0,0.4,3,0.5,0.5,0.5\n"         // theta_i below the horizon
      << "0.3,0,1.6,3,0.5,0.5,0.5\n"         // theta_o below the horizon
      << num(M_PI) << ",0,0.4,3,0.5,0.5,0.5\n"  // the writer's mark of a masked direction
      << "0.3,0," << num(M_PI / 2 + 1e-9) << ",3,0.5,0.5,0.5\n"
      << "0.5,1,0.2,2,0.5,0.5,0.5\n";
  }
  const SampleSet s = read_sample_csv(d.file("m.csv"));
  REQUIRE(s.size() == 6);
  CHECK(s.valid_count() == 2);
  CHECK(s.invalid_horizon == 4);
  CHECK(s.invalid_value == 0);
  CHECK(s.valid[0] == 1);
  CHECK(s.valid[5] == 1);
  for (const char* field : {"theta_i", "theta_o"})
    for (const double v : {3.2, -0.1}) {
      INFO(field << " = " << v);
      std::ofstream f(d.file("r.csv"));
      f << "# comment\ntheta_i,phi_i,theta_o,phi_o,r,g,b\n0.3,0,0.4,3,0.5,0.5,0.5\n";
      if (std::string(field) == "theta_i")
        f << num(v) << ",0,0.4,3,0.5,0.5,0.5\n";
      else
        f << "0.3,0," << num(v) << ",3,0.5,0.5,0.5\n";
      f.close();
      CHECK_THROWS_WITH(read_sample_csv(d.file("r.csv")),
                        Contains("r.csv:4: " + std::string(field) + " expected radians in [0, pi], found " + num(v)));
    }
}
