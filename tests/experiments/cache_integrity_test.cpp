// Caches inside the output folder are verified before they are trusted
// (docs/robustness.md "Caches are verified"): the sample cache
// (cache/samples/<key>.bin) and a finished run's files (runs/<id>/: DONE,
// run.json and the files it lists). A changed byte, a truncated file or a
// hand-made one is reported with its path (stderr and the run's notes), and
// the cache is rebuilt: the samples resampled, the run redone, so the table
// says what a clean run says. Every case runs the real CLI (a crash is an
// exit code, not the end of the test binary).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>

#include "experiments/plan/plan.h"
#include "experiments/report/outputs.h"
#include "experiments_helpers.h"
#include "process_helpers.h"

using namespace bf_test;
using Catch::Matchers::Contains;

namespace {

// Two cheap runs sharing one sample set.
const char* const kCacheConfig = R"([experiment]
name = "cache"
plots = false
[[brdf]]
preset = "bluepaint"
[sampling]
kind = "grid"
resolution = 6
[scene]
size = 16
[[method]]
kind = "mccool"
texture_size = [4, 6]
)";

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_bytes(const fs::path& p, const std::string& b) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << b;
}

// The one sample-cache entry of an output folder.
fs::path cache_file(const fs::path& out) {
  std::vector<fs::path> found;
  for (const auto& e : fs::directory_iterator(out / "cache" / "samples"))
    if (e.path().extension() == ".bin") found.push_back(e.path());
  REQUIRE(found.size() == 1);
  return found[0];
}

// Offsets of the sample cache's arrays (magic, six 64-bit counts, the
// description, wi, wo, values, weights, valid flags, then the content hash).
struct Layout {
  uint64_t n = 0, has_w = 0, dlen = 0;
  size_t wi = 0, wo = 0, value = 0, valid = 0, end = 0;
};

Layout layout_of(const std::string& b) {
  Layout l;
  REQUIRE(b.size() >= 56);
  std::memcpy(&l.n, b.data() + 8, 8);
  std::memcpy(&l.has_w, b.data() + 16, 8);
  std::memcpy(&l.dlen, b.data() + 48, 8);
  l.wi = 56 + l.dlen;
  l.wo = l.wi + l.n * 24;
  l.value = l.wo + l.n * 24;
  l.valid = l.value + l.n * 24 + (l.has_w ? l.n * 8 : 0);
  l.end = l.valid + l.n;
  REQUIRE(l.end <= b.size());
  return l;
}

void put_double(std::string& b, size_t at, double v) { std::memcpy(b.data() + at, &v, 8); }

// Re-signs an edited cache the way the writer does (64-bit FNV-1a of every
// byte before the 8-byte trailer), as a hand-made or hash-colliding file
// would be: then only the check of the decoded content stands in the way.
void resign(std::string& b) {
  const Layout l = layout_of(b);
  if (b.size() != l.end + 8) return;  // no trailer
  const uint64_t h = std::stoull(bf::content_hash(b.substr(0, l.end)), nullptr, 16);
  std::memcpy(b.data() + l.end, &h, 8);
}

std::string run_log(const fs::path& cfg, const fs::path& out, int* code) {
  std::string text;
  *code = run_cli_bounded({"run", cfg.string(), "--out", out.string(), "--no-plots", "-j", "1"}, out.string() + ".log",
                          300, &text);
  return text;
}

std::map<std::string, bf::Row> rows_by_id(const fs::path& out) {
  std::map<std::string, bf::Row> rows;
  for (auto& r : bf::read_results_csv((out / "results.csv").string())) rows[r["run_id"]] = r;
  return rows;
}

// The clean rows (computed once per test) and a folder whose caches a case corrupts.
struct Fixture {
  ScratchDir d;
  fs::path cfg, clean, out;
  std::map<std::string, bf::Row> clean_rows;
  Fixture() {
    cfg = write_text(d / "cache.toml", kCacheConfig);
    clean = d.path / "clean";
    out = d.path / "out";
    int code = 0;
    const std::string text = run_log(cfg, clean, &code);
    INFO(text);
    REQUIRE(code == 0);
    clean_rows = rows_by_id(clean);
    REQUIRE(clean_rows.size() == 2);
    fs::copy(clean, out, fs::copy_options::recursive);
  }
  // Runs the folder again with its runs removed, so both read the sample cache.
  std::string rerun_without_runs(int* code) {
    fs::remove_all(out / "runs");
    return run_log(cfg, out, code);
  }
  // Every row of `out` has the clean row's metrics and status ok.
  void check_rows_equal_clean() {
    const auto rows = rows_by_id(out);
    REQUIRE(rows.size() == clean_rows.size());
    for (const auto& [id, clean_row] : clean_rows) {
      INFO(id);
      REQUIRE(rows.count(id));
      const bf::Row& r = rows.at(id);
      CHECK(r.at("status") == "ok");
      for (const char* k : {"rel_mse", "rel_max", "lin_rmse", "cos_rmse", "val_rel_mse", "shade_rmse", "samples"})
        CHECK(r.at(k) == clean_row.at(k));
    }
  }
  std::string notes() {
    std::string all;
    for (const auto& [id, r] : rows_by_id(out)) all += r.at("notes") + "\n";
    return all;
  }
};

}  // namespace

TEST_CASE("cache integrity: a changed value byte in the sample cache is reported and the samples rebuilt") {
  Fixture f;
  const fs::path cache = cache_file(f.out);
  std::string b = read_bytes(cache);
  const Layout l = layout_of(b);
  // One byte of one value: the exponent of sample 10's red channel.
  b[l.value + 10 * 24 + 7] ^= 0x20;
  write_bytes(cache, b);
  int code = 0;
  const std::string text = f.rerun_without_runs(&code);
  INFO(text);
  CHECK(code == 0);
  CHECK_THAT(text, Contains("warning") && Contains(cache.string()));
  f.check_rows_equal_clean();
  CHECK_THAT(f.notes(), Contains(cache.string()));
  // Rebuilt: the next run trusts it again, silently.
  const std::string again = f.rerun_without_runs(&code);
  INFO(again);
  CHECK(code == 0);
  CHECK(again.find("warning") == std::string::npos);
  CHECK(read_bytes(cache) == read_bytes(cache_file(f.clean)));
}

TEST_CASE("cache integrity: a truncated sample cache is reported and rebuilt") {
  Fixture f;
  const fs::path cache = cache_file(f.out);
  std::string b = read_bytes(cache);
  for (const size_t keep : {b.size() - 1, b.size() / 2, size_t{20}, size_t{0}}) {
    INFO("kept " << keep << " of " << b.size() << " bytes");
    write_bytes(cache, b.substr(0, keep));
    int code = 0;
    const std::string text = f.rerun_without_runs(&code);
    INFO(text);
    CHECK(code == 0);
    CHECK_THAT(text, Contains("warning") && Contains(cache.string()));
    f.check_rows_equal_clean();
  }
}

TEST_CASE("cache integrity: a NaN direction marked valid cannot crash a run, even with a matching hash") {
  for (const bool signed_again : {false, true}) {
    INFO((signed_again ? "hash recomputed" : "hash left stale"));
    Fixture f;
    const fs::path cache = cache_file(f.out);
    std::string b = read_bytes(cache);
    const Layout l = layout_of(b);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (int k : {3, 50}) {
      put_double(b, l.wi + k * 24, nan);  // wi.x of sample k
      put_double(b, l.wo + k * 24 + 16, nan);  // wo.z
      b[l.valid + k] = 1;
    }
    if (signed_again) resign(b);
    write_bytes(cache, b);
    int code = 0;
    const std::string text = f.rerun_without_runs(&code);
    INFO(text);
    CHECK(code == 0);  // not -1 (SIGSEGV)
    CHECK_THAT(text, Contains("warning") && Contains(cache.string()));
    f.check_rows_equal_clean();
  }
}

TEST_CASE("cache integrity: non-finite values, bad flags and wrong counts in the sample cache are rebuilt") {
  const double inf = std::numeric_limits<double>::infinity();
  // Each edit keeps the file's size; the hash is recomputed, so the decoded
  // content is what must be refused.
  const std::vector<std::pair<std::string, std::function<void(std::string&, const Layout&)>>> edits = {
      {"inf value marked valid", [&](std::string& b, const Layout& l) { put_double(b, l.value + 7 * 24, inf); }},
      {"NaN value marked valid",
       [&](std::string& b, const Layout& l) {
         put_double(b, l.value + 8 * 24 + 8, std::numeric_limits<double>::quiet_NaN());
       }},
      {"negative value marked valid", [&](std::string& b, const Layout& l) { put_double(b, l.value + 9 * 24, -1.0); }},
      {"valid flag 7", [&](std::string& b, const Layout& l) { b[l.valid + 4] = 7; }},
      {"a valid sample masked", [&](std::string& b, const Layout& l) { b[l.valid + 5] = 0; }},
      {"a direction not of unit length",
       [&](std::string& b, const Layout& l) { put_double(b, l.wi + 6 * 24 + 16, 5.0); }},
      {"a masked count that disagrees", [&](std::string& b, const Layout&) { b[24] = 3; }},
      {"the wrong description text", [&](std::string& b, const Layout& l) { if (l.dlen) b[56] = '\x01'; }},
  };
  Fixture f;  // one clean run; each edit starts from its cache
  const fs::path cache = cache_file(f.out);
  const std::string clean_bytes = read_bytes(cache_file(f.clean));
  for (const auto& [what, edit] : edits) {
    INFO(what);
    std::string b = clean_bytes;
    edit(b, layout_of(b));
    resign(b);
    REQUIRE(b != clean_bytes);
    write_bytes(cache, b);
    int code = 0;
    const std::string text = f.rerun_without_runs(&code);
    INFO(text);
    CHECK(code == 0);
    CHECK_THAT(text, Contains("warning") && Contains(cache.string()));
    f.check_rows_equal_clean();
  }
}

TEST_CASE("cache integrity: a changed finished-run record is reported and the run redone") {
  Fixture f;
  const auto ids = [&] {
    std::vector<std::string> v;
    for (const auto& [id, r] : f.clean_rows) v.push_back(id);
    return v;
  }();
  const fs::path run_dir = f.out / "runs" / ids[0];
  SECTION("a metric in run.json") {
    nlohmann::json rec = nlohmann::json::parse(read_text((run_dir / "run.json").string()));
    rec["row"]["rel_mse"] = "0.000001";
    write_text((run_dir / "run.json").string(), rec.dump(2) + "\n");
  }
  SECTION("one byte of run.json") {
    std::string b = read_bytes(run_dir / "run.json");
    const size_t at = b.find("\"rel_mse\": \"");
    REQUIRE(at != std::string::npos);
    b[at + 13] = b[at + 13] == '1' ? '2' : '1';
    write_bytes(run_dir / "run.json", b);
  }
  SECTION("a byte of a listed file") {
    std::string b = read_bytes(run_dir / "factors.json");
    b[b.size() / 2] ^= 0x01;
    write_bytes(run_dir / "factors.json", b);
  }
  SECTION("a listed file replaced by a link to a copy") {
    fs::copy_file(run_dir / "factors.json", f.d.path / "elsewhere.json");
    fs::remove(run_dir / "factors.json");
    fs::create_symlink(f.d.path / "elsewhere.json", run_dir / "factors.json");
  }
  SECTION("a DONE marker without content hashes") {
    write_text((run_dir / "DONE").string(), ids[0] + "\n");
  }
  SECTION("a DONE marker that is not text") {
    write_bytes(run_dir / "DONE", std::string("\x00\xff{\x01", 4));
  }
  SECTION("a truncated run.json") {
    const std::string b = read_bytes(run_dir / "run.json");
    write_bytes(run_dir / "run.json", b.substr(0, b.size() - 10));
  }
  const auto done_before = fs::last_write_time(f.out / "runs" / ids[1] / "DONE");
  int code = 0;
  const std::string text = run_log(f.cfg, f.out, &code);
  INFO(text);
  CHECK(code == 0);
  CHECK_THAT(text, Contains("warning") && Contains(run_dir.string()) && Contains("redone"));
  CHECK_THAT(text, Contains("1 run, 1 cached, 0 failed"));
  f.check_rows_equal_clean();
  CHECK_THAT(rows_by_id(f.out).at(ids[0]).at("notes"), Contains(run_dir.string()));
  CHECK(fs::last_write_time(f.out / "runs" / ids[1] / "DONE") == done_before);  // the intact run was reused
  CHECK(fs::is_regular_file(fs::symlink_status(run_dir / "factors.json")));
  // The redone run verifies: the next run reuses both, silently.
  const std::string again = run_log(f.cfg, f.out, &code);
  INFO(again);
  CHECK(code == 0);
  CHECK_THAT(again, Contains("0 run, 2 cached, 0 failed"));
  CHECK(again.find("warning") == std::string::npos);
}

TEST_CASE("cache integrity: samples read from the cache declare their BRDF's symmetries as fresh ones do") {
  // The cache holds the data, not the declaration: a run that reads it must
  // record (and decide on) the same symmetries as the run that sampled it.
  Fixture f;
  int code = 0;
  const std::string text = f.rerun_without_runs(&code);
  INFO(text);
  REQUIRE(code == 0);
  const auto declared = [](const fs::path& out) {
    std::vector<std::string> all;
    for (const auto& e : fs::directory_iterator(out / "runs")) {
      std::ifstream in(e.path() / "run.json");
      all.push_back(nlohmann::json::parse(in).at("symmetries").at("declared").get<std::string>());
    }
    return all;
  };
  const std::vector<std::string> fresh = declared(f.clean), cached = declared(f.out);
  REQUIRE(fresh.size() == 2);
  CHECK(cached == fresh);
  for (const std::string& s : cached) CHECK(s == "isotropic+reciprocal+bilateral");  // bluepaint's claim
}
