// Tests of the sample-list CSV reader and writer: round trip, masking, and
// every failure kind (small bad files under tests/data/measured/).
#include "brdfs/sample_csv.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
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

using bf_test::TempDir;

std::string bad_csv(const std::string& name) {
  return std::string(BF_TEST_DATA_DIR) + "/measured/" + name;
}

using bf_test::slurp;

}  // namespace

TEST_CASE("csv: write then read round-trips directions, values, weights and masks") {
  TempDir d("csv_rt");
  LambertParams lp;
  lp.kd = Rgb(0.1, 0.2, 0.3);
  SampleSet s = sample_stratified(Lambert(lp), 200, 4);
  s.weight.assign(s.size(), 1.0);
  for (size_t k = 0; k < s.size(); ++k) s.weight[k] = 0.5 + 0.01 * double(k);
  // Masked samples of every kind, including non-finite ones.
  s.value[3] = Rgb(std::nan(""), 0.1, 0.1);
  s.value[4] = Rgb(-0.5, 0.1, 0.1);
  s.value[5] = Rgb(HUGE_VAL, 0.1, 0.1);
  s.wo[6] = from_spherical(2.0, 1.0);
  s.wi[7] = Vec3(std::nan(""), 0, 1);
  s.weight[8] = std::nan("");
  s.weight[9] = -1.0;
  s.description = "two\nlines";
  s.validate();
  REQUIRE(s.valid_count() == 193);
  const std::string p = d.file("rt.csv");
  write_sample_csv(s, p);
  CHECK_FALSE(fs::exists(p + ".tmp"));
  const std::string text = slurp(p);
  CHECK(text.find("nan") == std::string::npos);
  CHECK(text.find("inf") == std::string::npos);
  CHECK(text.rfind("# two lines\ntheta_i,phi_i,theta_o,phi_o,r,g,b,weight\n", 0) == 0);
  const SampleSet r = read_sample_csv(p);
  REQUIRE(r.size() == s.size());
  CHECK(r.valid == s.valid);
  CHECK(r.invalid_value == s.invalid_value);
  CHECK(r.invalid_horizon == s.invalid_horizon);
  CHECK(r.invalid_weight == s.invalid_weight);
  for (size_t k = 0; k < s.size(); ++k) {
    if (!s.valid[k]) continue;
    INFO("sample " << k);
    CHECK((r.wi[k] - s.wi[k]).norm() < 1e-14);
    CHECK((r.wo[k] - s.wo[k]).norm() < 1e-14);
    CHECK((r.value[k] == s.value[k]).all());
    CHECK(r.weight[k] == s.weight[k]);
  }
  // Without weights there is no weight column.
  const SampleSet g = sample_grid(Lambert(lp), 4);
  write_sample_csv(g, p);
  const SampleSet rg = read_sample_csv(p);
  CHECK(rg.weight.empty());
  CHECK(rg.size() == g.size());
  CHECK(slurp(p).find("weight") == std::string::npos);
}

TEST_CASE("csv: masked rows are kept and counted, CRLF and BOM are fine") {
  const SampleSet s = read_sample_csv(bad_csv("csv_masked.csv"));
  REQUIRE(s.size() == 6);
  CHECK(s.valid_count() == 1);
  CHECK(s.invalid_value == 3);  // NaN, negative, overflow (1e999)
  CHECK(s.invalid_horizon == 1);
  CHECK(s.invalid_weight == 1);
  TempDir d("csv_bom");
  {
    std::ofstream f(d.file("bom.csv"), std::ios::binary);
    f << "\xEF\xBB\xBFtheta_i,phi_i,theta_o,phi_o,r,g,b\r\n 0.1 , 0 , 0.2 , 3.1 , 0.5 , 0.5 , "
         "1e-320 \r\n";
  }
  const SampleSet b = read_sample_csv(d.file("bom.csv"));
  REQUIRE(b.size() == 1);
  CHECK(b.valid_count() == 1);  // an underflowing value reads as (nearly) 0, not an error
  // A sample list is also a measured BRDF (isotropic interpolation).
  const BrdfPtr m = Catalogue::builtin().make(bad_csv("csv_masked.csv") + ":k=2");
  CHECK(measured_samples(*m).size() == 6);
  CHECK(m->eval(from_spherical(0.1, 0.0), from_spherical(0.2, 3.1)).isApprox(Rgb::Constant(0.5)));
  CHECK_THROWS_WITH(Catalogue::builtin().make(bad_csv("csv_masked.csv") + ":band=550"),
                    Contains("unknown parameter 'band' for the .csv loader"));
}

TEST_CASE("csv: every failure kind gives path:line, expected and found") {
  struct Case {
    const char* file;
    const char* message;
  };
  const Case cases[] = {
      {"csv_bad_header.csv",
       "csv_bad_header.csv:2: header column 1 expected 'theta_i', found "
       "'theta_in'"},
      {"csv_header_cols.csv",
       "csv_header_cols.csv:1: expected header theta_i,phi_i,theta_o,phi_o,"
       "r,g,b[,weight], found 6 columns"},
      {"csv_row_cols.csv", "csv_row_cols.csv:3: expected 7 columns (as in the header), found 6"},
      {"csv_not_number.csv", "csv_not_number.csv:3: column 6 (g) expected a number, found 'abc'"},
      {"csv_empty_cell.csv", "csv_empty_cell.csv:2: column 6 (g) expected a number, found ''"},
      {"csv_theta_range.csv",
       "csv_theta_range.csv:2: theta_o expected radians in [0, pi], found "
       "4.0"},
      {"csv_phi_range.csv",
       "csv_phi_range.csv:2: phi_i expected radians in [-2pi, 2pi], found 7.0"},
      {"csv_nan_angle.csv", "csv_nan_angle.csv:2: theta_i expected radians in [0, pi], found nan"},
      {"csv_empty.csv",
       "expected a header line theta_i,phi_i,theta_o,phi_o,r,g,b[,weight], found "
       "an empty file (or only comments)"},
      {"csv_header_only.csv", "expected at least one sample after the header, found none"},
  };
  for (const Case& c : cases) {
    INFO(c.file);
    CHECK_THROWS_AS(read_sample_csv(bad_csv(c.file)), std::invalid_argument);
    CHECK_THROWS_WITH(read_sample_csv(bad_csv(c.file)), Contains(c.message));
  }
  CHECK_THROWS_WITH(read_sample_csv(bad_csv("absent.csv")), Contains("absent.csv: cannot open"));
  TempDir d("csv_bad");
  {
    std::ofstream f(d.file("long.csv"));
    f << "theta_i,phi_i,theta_o,phi_o,r,g,b\n" << std::string(100000, '1') << "\n";
  }
  CHECK_THROWS_WITH(read_sample_csv(d.file("long.csv")),
                    Contains("long.csv:2: expected a line of at most 65536 characters"));
  {
    std::ofstream f(d.file("hex.csv"));
    f << "theta_i,phi_i,theta_o,phi_o,r,g,b\n0x1p-2,0,0.2,3.1,0.5,0.5,0.5\n";
  }
  CHECK_THROWS_WITH(read_sample_csv(d.file("hex.csv")), Contains("found '0x1p-2'"));
  // The writer reports an unwritable path and leaves nothing behind.
  CHECK_THROWS_WITH(
      write_sample_csv(sample_grid(Lambert(LambertParams{}), 4), d.file("no/such/dir/x.csv")),
      Contains("cannot open"));
}
