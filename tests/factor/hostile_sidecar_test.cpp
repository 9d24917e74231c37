// Hostile export sidecars of the SVD / SH-K / SH-R baselines
// (factor/baseline_export.h): every count a sidecar declares (orders,
// resolutions, rank, data.values, block counts) is bounded by the documented
// option ranges and checked against the data file's actual size before
// anything is allocated or read. Each case asserts the message (file, field,
// expected, found); the CLI cases run `brdf-factor eval --brdf SIDECAR` under
// an address-space limit and a timeout, so an allocation from a declared count
// fails the test instead of the machine.
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "brdfs/file_check.h"
#include "brdfs/models.h"
#include "experiments/process_helpers.h"
#include "factor/baseline_export.h"
#include "factor/sh_baseline.h"
#include "factor/svd_baseline.h"
#include "test_common.h"

using namespace bf;
using bf_test::TempDir;
using Catch::Contains;
using nlohmann::json;

namespace {

Ward ward() {
  WardParams p;
  p.kd = Rgb(0.3, 0.25, 0.2);
  p.ks = Rgb(0.2, 0.25, 0.3);
  p.ax = p.ay = 0.3;
  return Ward(p);
}

json read_sidecar_json(const std::string& path) {
  std::ifstream in(path);
  return json::parse(in);
}

void write_sidecar_json(const std::string& path, const json& j) { std::ofstream(path) << j.dump(1); }

// n float64 zeros (8 n bytes) at path.
void write_zeros(const std::string& path, size_t n) {
  const std::vector<double> v(n, 0.0);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(n * 8));
}

// A sparse file of `bytes` (no disk space used, no page touched).
void write_sparse(const std::string& path, uint64_t bytes) {
  { std::ofstream(path, std::ios::binary | std::ios::trunc); }
  REQUIRE(::truncate(path.c_str(), off_t(bytes)) == 0);
}

// Points block `name` at `count` values from offset 0.
void set_block(json& j, const std::string& name, size_t count) {
  for (json& b : j["data"]["blocks"])
    if (b["name"] == name) {
      b["offset"] = 0;
      b["count"] = count;
    }
}

// Exit code and output of `brdf-factor eval --brdf sidecar` with at most 400 MB
// of address space and 30 s.
int cli_eval(const TempDir& d, const std::string& sidecar, std::string* out) {
  return bf_test::run_cli_bounded({"eval", "--brdf", sidecar, "--wi", "0,0,1", "--wo", "0,0,1"}, d.file("cli.log"), 30,
                                  out, 400);
}

// A small SH-R export (order 2, view order 1) in d, as the run writes it.
BaselineExportFiles shr_export(const TempDir& d) {
  ShrOptions o;
  o.max_order = 2;
  o.max_view_order = 1;
  o.order = 2;
  o.view_order = 1;
  return write_baseline_export(*fit_shr(ward(), o), d.path.string(), "factors");
}

}  // namespace

TEST_CASE("hostile sidecars: the address-space limit of these tests lets a valid export load") {
  TempDir d("hostile_sidecar_ok");
  const BaselineExportFiles files = shr_export(d);
  std::string out;
  CHECK(cli_eval(d, files.sidecar, &out) == 0);
  INFO(out);
  CHECK(load_baseline_export(files.sidecar)->method() == "sh-r");
}

TEST_CASE("hostile sidecars: sh-r orders beyond the fit's ranges are refused before the table is allocated") {
  TempDir d("hostile_sidecar_shr");
  const BaselineExportFiles files = shr_export(d);
  json j = read_sidecar_json(files.sidecar);
  SECTION("view_order 2000 with a data file that holds its coefficients (48 KB)") {
    // order 0, view order 2000: 2001 coefficients per channel, but a table of
    // 2001^2 per channel (199 MB before the check).
    j["order"] = 0;
    j["view_order"] = 2000;
    const size_t M = 2001;
    j["data"]["values"] = 3 * M;
    set_block(j, "rho", 3 * M);
    write_sidecar_json(files.sidecar, j);
    write_zeros(files.data, 3 * M);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains(files.sidecar) && Contains("field 'view_order': expected an integer in 0..32, found 2000"));
    std::string out;
    CHECK(cli_eval(d, files.sidecar, &out) == 2);
    CHECK_THAT(out, Contains("field 'view_order': expected an integer in 0..32, found 2000"));
  }
  SECTION("order 2000") {
    j["order"] = 2000;
    j["view_order"] = 0;
    j["data"]["values"] = 3 * 2001;
    set_block(j, "rho", 3 * 2001);
    write_sidecar_json(files.sidecar, j);
    write_zeros(files.data, 3 * 2001);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains(files.sidecar) && Contains("field 'order': expected an integer in 0..200, found 2000"));
  }
  SECTION("the largest orders with a data file of 24 values") {
    j["order"] = ShrOptions::kMaxOrder;
    j["view_order"] = ShrOptions::kMaxViewOrder;
    const size_t M = shr_coefficient_count(ShrOptions::kMaxOrder, ShrOptions::kMaxViewOrder);
    j["data"]["values"] = 3 * M;
    set_block(j, "rho", 3 * M);
    write_sidecar_json(files.sidecar, j);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains(files.data) && Contains("expected " + std::to_string(3 * M * 8) + " bytes") &&
                          Contains("data.values of " + files.sidecar) && Contains("found 192"));
  }
}

TEST_CASE("hostile sidecars: data.values is bounded by the data-file cap and by the blocks before the file is read") {
  TempDir d("hostile_sidecar_values");
  const BaselineExportFiles files = shr_export(d);
  const json j0 = read_sidecar_json(files.sidecar);
  const size_t n = 3 * shr_coefficient_count(2, 1);
  REQUIRE(j0["data"]["values"] == n);
  SECTION("2^31 values (16 GiB) are beyond the cap of every data file") {
    json j = j0;
    j["data"]["values"] = 1LL << 31;
    write_sidecar_json(files.sidecar, j);
    const std::string msg = "field 'data.values': expected an integer in 0.." +
                            std::to_string(kMaxDataFileBytes / 8) + " (a data file of at most " +
                            std::to_string(kMaxDataFileBytes) + " bytes), found 2147483648";
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains(files.sidecar) && Contains(msg));
    std::string out;
    CHECK(cli_eval(d, files.sidecar, &out) == 2);
    CHECK_THAT(out, Contains(msg));
  }
  SECTION("data.values larger than the blocks, with a data file of that size (800 MB, sparse)") {
    json j = j0;
    j["data"]["values"] = 100000000;
    write_sidecar_json(files.sidecar, j);
    write_sparse(files.data, 800000000ULL);
    const std::string msg = "field 'data.values': expected " + std::to_string(n) +
                            " (the blocks of order 2 and view_order 1), found 100000000";
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains(files.sidecar) && Contains(msg));
    std::string out;
    CHECK(cli_eval(d, files.sidecar, &out) == 2);
    CHECK_THAT(out, Contains(msg));
  }
  SECTION("a data file beyond the data-file cap is refused from its size") {
    write_sparse(files.data, kMaxDataFileBytes + 8);
    const std::string msg = files.data + ": data file: " + std::to_string(kMaxDataFileBytes + 8) +
                            " bytes, more than the limit of " + std::to_string(kMaxDataFileBytes);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains(msg));
    std::string out;
    CHECK(cli_eval(d, files.sidecar, &out) == 2);
    CHECK_THAT(out, Contains(msg));
  }
  SECTION("a FIFO or a folder as the data file") {
    std::filesystem::remove(files.data);
    REQUIRE(::mkfifo(files.data.c_str(), 0600) == 0);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains(files.data + ": data file: expected a regular file, found a FIFO"));
    std::string out;
    CHECK(cli_eval(d, files.sidecar, &out) == 2);
    CHECK_THAT(out, Contains(files.data + ": data file: expected a regular file, found a FIFO"));
    std::filesystem::remove(files.data);
    std::filesystem::create_directory(files.data);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains(files.data + ": data file: expected a regular file, found a directory"));
  }
  SECTION("a FIFO as the sidecar") {
    const std::string fifo = d.file("pipe.json");
    REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
    CHECK_THROWS_WITH(load_baseline_export(fifo),
                      Contains(fifo + ": factorization sidecar: expected a regular file, found a FIFO"));
    CHECK_THROWS_WITH(sidecar_method(fifo),
                      Contains(fifo + ": factorization sidecar: expected a regular file, found a FIFO"));
  }
}

TEST_CASE("hostile sidecars: svd and sh-k sizes are bounded by their option ranges and the data file") {
  TempDir d("hostile_sidecar_svd");
  SECTION("svd") {
    SvdOptions o;
    o.res = 6;
    o.rank = 1;
    const BaselineExportFiles files = write_baseline_export(*fit_svd(ward(), o), d.path.string(), "svd");
    json j = read_sidecar_json(files.sidecar);
    const size_t n = DiskGrid::make(6).count();
    j["rank"] = n + 1;
    write_sidecar_json(files.sidecar, j);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains("field 'rank': expected an integer in 1.." + std::to_string(n) + ", found " +
                               std::to_string(n + 1)));
    // The largest resolution and full rank, declared with a data file of the export's few values.
    j["resolution"] = 256;
    const size_t n256 = DiskGrid::make(256).count();
    j["rank"] = n256;
    set_block(j, "sigma", 3 * n256);
    set_block(j, "u", 3 * n256 * 65536);
    set_block(j, "v", 3 * n256 * 65536);
    write_sidecar_json(files.sidecar, j);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains(files.sidecar) && Contains("data.blocks[") && Contains(".offset") &&
                          Contains("-value data file (data.values)"));
  }
  SECTION("sh-k") {
    ShkOptions o;
    o.order = 1;
    o.view_res = 6;
    o.theta_nodes = 8;
    o.phi_nodes = 16;
    const BaselineExportFiles files = write_baseline_export(*fit_shk(ward(), o), d.path.string(), "shk");
    const json j0 = read_sidecar_json(files.sidecar);
    const std::pair<const char*, json> cases[] = {
        {"order", ShkOptions::kMaxOrder + 1},
        {"view_resolution", ShkOptions::kMaxTextureSize + 1},
    };
    for (const auto& [key, v] : cases) {
      json j = j0;
      j[key] = v;
      write_sidecar_json(files.sidecar, j);
      CHECK_THROWS_WITH(load_baseline_export(files.sidecar), Contains(std::string("field '") + key + "'") &&
                                                                 Contains("found " + v.dump()));
    }
    json j = j0;
    j["quadrature"]["theta_nodes"] = 1 << 20;
    write_sidecar_json(files.sidecar, j);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains("field 'theta_nodes': expected an integer in 1.." +
                               std::to_string(ShkOptions::kMaxThetaNodes) + ", found 1048576"));
    // The largest order and resolution, with the export's small data file.
    j = j0;
    j["order"] = ShkOptions::kMaxOrder;
    j["view_resolution"] = ShkOptions::kMaxTextureSize;
    const size_t count = size_t(3) * 101 * 101 * 512 * 512;
    j["data"]["values"] = 1000;
    set_block(j, "coefficients", count);
    write_sidecar_json(files.sidecar, j);
    CHECK_THROWS_WITH(load_baseline_export(files.sidecar),
                      Contains(files.sidecar) && Contains(".offset") && Contains("-value data file (data.values)"));
  }
}
