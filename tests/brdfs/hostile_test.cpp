// Hostile input (docs/design.md §7): every file under tests/data/hostile/ makes the
// CLI exit 2 with one message naming the file and saying what was wrong,
// never a crash; the measured readers also reject them directly.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "brdfs/catalogue.h"

using namespace bf;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

std::string hostile(const std::string& name) { return std::string(BF_TEST_DATA_DIR) + "/hostile/" + name; }

// Runs the CLI; returns the exit code (-1 if it did not exit normally, e.g. a
// crash), stderr into *err.
int run_cli_hostile(const std::string& args, std::string* err) {
  static int counter = 0;
  const fs::path errfile = fs::temp_directory_path() /
                           ("bf_hostile_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".txt");
  std::string cmd = BF_CLI_PATH;
  cmd.append(" ").append(args).append(" > /dev/null 2> ").append(errfile.string());
  const int status = std::system(cmd.c_str());
  std::ifstream in(errfile);
  std::stringstream ss;
  ss << in.rdbuf();
  *err = ss.str();
  std::error_code ec;
  fs::remove(errfile, ec);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

struct Hostile {
  const char* file;
  const char* message;     // part of the expected message
  bool names_file = true;  // false: the message need not contain the path
};

}  // namespace

TEST_CASE("hostile: measured and sidecar files exit 2 with a message naming the file") {
  const Hostile cases[] = {
      {"astm_binary_header.astm", "expected a header line 'KEY value'"},
      {"astm_cut_mid_row.astm", ":6: expected 35 comma-separated values (4 angles, 31 bands), found 6"},
      {"astm_negative_num_points.astm", ":3: NUM_POINTS expected an integer in 1..10000000, found '-5'"},
      {"astm_nonutf8.astm", ":6: column 4 (phi_s) expected a number, found '\\xFF\\xFE"},
      {"astm_nul.astm", ":6: column 4 (phi_s) expected a number, found '3.1\\x00'"},
      {"astm_overflow.astm", ":6: column 5 (400nm) expected a finite number, found '1e400'"},
      {"brdf_float_nwl.brdf", ":1: expected the number of wavelengths (31), found '31.5'"},
      {"brdf_hex.brdf", "record 1 theta_i expected a number, found '0x1p3'"},
      {"brdf_negative_nwl.brdf", "found '-31'"},
      {"brdf_nonutf8.brdf", "record 1 phi_s expected a number, found '\\xFF\\xFE'"},
      {"brdf_overflow.brdf", "record 1 400nm expected a finite number, found '1e999'"},
      {"csv_binary.csv", ":1: expected header theta_i,phi_i,theta_o,phi_o,r,g,b[,weight]"},
      {"csv_hex_float.csv", ":2: column 1 (theta_i) expected a number, found '0x1p-2'"},
      {"csv_nonutf8.csv", ":2: column 5 (r) expected a number, found '\\xFF\\xFE'"},
      {"csv_nul.csv", ":2: column 3 (theta_o) expected a number, found '0.2\\x00'"},
      // Every row masked.
      {"csv_overflow.csv", "expected at least one valid sample, found none"},
      {"csv_negative_weight_only.csv", "expected at least one valid sample, found none"},
      {"json_array.json", "expected a JSON object, found array"},
      {"json_deep.json", "expected a JSON object, found array"},
      {"json_deep_object.json", "field 'format': expected a string"},
      {"json_empty.json", "invalid JSON"},
      {"json_nan.json", "invalid JSON"},
      {"json_nonutf8.json", "ill-formed UTF-8"},
      {"json_truncated.json", "invalid JSON"},
      {"json_wrong_types.json", "field 'format': expected a string, found number 7"},
      // nlohmann's out_of_range for a number beyond double's range.
      {"json_huge_version.json", "invalid JSON: [json.exception.out_of_range.406] number overflow parsing '1e400'"},
  };
  for (const Hostile& c : cases) {
    INFO(c.file);
    std::string err;
    CHECK(run_cli_hostile("eval --brdf " + hostile(c.file) + " --wi 0,0,1 --wo 0,0,1", &err) == 2);
    CHECK_THAT(err, Contains("brdf-factor: ") && Contains(c.message));
    if (c.names_file) CHECK_THAT(err, Contains(c.file));
    CHECK(std::count(err.begin(), err.end(), '\n') == 1);
  }
}

TEST_CASE("hostile: the measured readers throw for every hostile measured file") {
  for (const auto& e : fs::directory_iterator(std::string(BF_TEST_DATA_DIR) + "/hostile")) {
    const std::string ext = e.path().extension().string();
    if (ext != ".astm" && ext != ".brdf" && ext != ".csv") continue;
    INFO(e.path().string());
    CHECK_THROWS_AS(Catalogue::builtin().make(e.path().string()), std::exception);
  }
}

TEST_CASE("hostile: bad configs exit 2 with a message naming the file") {
  const Hostile cases[] = {
      {"config_binary.toml", "TOML"},
      {"config_deep.toml", "maximum nested value depth"},
      {"config_deep_tables.toml", "TOML: a key nests 257 tables deep"},
      {"config_empty.toml", "the config needs at least one [[brdf]] table"},
      {"config_huge_array.toml", "unknown section"},
      {"config_nonutf8.toml", "invalid utf-8"},
      {"config_nul.toml", "control characters"},
      {"config_truncated.toml", "end-of-file"},
      {"config_wrong_types.toml", "expected a [experiment] table, found 5"},
  };
  for (const Hostile& c : cases) {
    INFO(c.file);
    std::string err;
    CHECK(run_cli_hostile("run " + hostile(c.file) + " --dry-run", &err) == 2);
    CHECK_THAT(err, Contains(c.message) && Contains(c.file));
  }
}
