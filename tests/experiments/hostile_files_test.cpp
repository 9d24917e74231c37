// Hostile input (docs/robustness.md, "Promises and the tests that check them"): files that name files, and
// the readers' bounds. Every case runs the real CLI and expects exit 2 with
// one message naming the offending file, never a crash.
#include <sys/stat.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "brdfs/safe_path.h"
#include "experiments/plan/toml_depth.h"
#include "experiments_helpers.h"
#include "factor/metrics.h"
#include "process_helpers.h"

using namespace bf_test;
using Catch::Matchers::Contains;

namespace {

std::string model_fit_json(const std::string& spec) {
  return R"({"format": "brdf-factor-model-fit", "format_version": 1, "spec": ")" + spec + "\"}\n";
}

// eval and run --dry-run on `file` both exit 2 with a message containing every fragment.
void expect_eval_and_dry_run_refuse(const ScratchDir& d, const std::string& file,
                                    std::initializer_list<std::string> fragments) {
  std::string text = "[experiment]\nname = \"t\"\n[[brdf]]\nfile = \"";
  text.append(file).append("\"\n[sampling]\nkind = \"grid\"\nresolution = 6\n");
  text.append("[[method]]\nkind = \"svd\"\nterms = 1\ntexture_size = 6\n");
  const std::string cfg = write_text(d / "cfg.toml", text);
  std::vector<std::string> commands(2);
  commands[0].append("eval --brdf ").append(file).append(" --wi 0,0,1 --wo 0,0,1");
  commands[1].append("run ").append(cfg).append(" --dry-run --out ").append(d / "out");
  for (const std::string& args : commands) {
    INFO(args);
    std::string err;
    CHECK(run_cli_stderr(args, &err) == 2);
    INFO(err);
    CHECK_THAT(err, Contains("brdf-factor: "));
    for (const auto& f : fragments) CHECK_THAT(err, Contains(f));
  }
}

}  // namespace

TEST_CASE("hostile files: a model fit whose spec names itself or a cycle is refused, not recursed into") {
  ScratchDir d;
  SECTION("itself") {
    const std::string a = write_text(d / "a.json", model_fit_json(d / "a.json"));
    expect_eval_and_dry_run_refuse(d, a, {"a.json: refers back to a file being loaded"});
  }
  SECTION("a -> b -> a") {
    const std::string a = write_text(d / "a.json", model_fit_json(d / "b.json"));
    write_text(d / "b.json", model_fit_json(d / "a.json"));
    expect_eval_and_dry_run_refuse(d, a, {"refers back to a file being loaded", "a.json -> ", "b.json -> "});
  }
  SECTION("a chain of distinct files deeper than the limit") {
    for (int i = 0; i < 40; ++i)
      write_text(d / ("m" + std::to_string(i) + ".json"), model_fit_json(d / ("m" + std::to_string(i + 1) + ".json")));
    write_text(d / "m40.json", model_fit_json("lambert"));
    expect_eval_and_dry_run_refuse(d, d / "m0.json", {"files name each other more than 8 deep"});
  }
  SECTION("a short chain still loads") {
    write_text(d / "x.json", model_fit_json(d / "y.json"));
    write_text(d / "y.json", model_fit_json("lambert"));
    std::string err;
    CHECK(run_cli_stderr("eval --brdf " + (d / "x.json") + " --wi 0,0,1 --wo 0,0,1", &err) == 0);
    CHECK(err.empty());
  }
}

// ------------------------------------------------------------------ helpers for the classes below

namespace {

// A real sidecar: a one-run experiment (mccool at 6x6) exports runs/<id>/factors.json.
std::string exported_sidecar(const ScratchDir& d) {
  const std::string cfg = write_text(d / "exp.toml", std::string(kConfigHead) +
                                                        "[[method]]\nkind = \"mccool\"\ntexture_size = 6\n");
  run_quiet(cfg, d / "exp");
  for (const auto& e : fs::recursive_directory_iterator(d.path / "exp" / "runs"))
    if (e.path().filename() == "factors.json") return e.path().string();
  return "";
}

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(read_text(path)); }

std::string cli_log(const ScratchDir& d) {
  static int n = 0;
  return d / ("cli" + std::to_string(n++) + ".log");
}

}  // namespace

TEST_CASE("hostile files: FIFOs, devices and folders given as data files are refused at once") {
  ScratchDir d;
  const std::string sidecar = exported_sidecar(d);
  REQUIRE(!sidecar.empty());
  for (const char* name : {"pipe.csv", "pipe.astm", "pipe.brdf", "pipe.json"})
    REQUIRE(::mkfifo((d / name).c_str(), 0600) == 0);
  fs::create_directories(d.path / "folder.csv");
  struct Case {
    std::string brdf, message;
  };
  // A sidecar whose texture is a FIFO, and one whose texture is a link to
  // /dev/zero inside the folder (refused as a link before it is opened); a
  // data file given on the command line as a link to /dev/zero.
  const fs::path folder = fs::path(sidecar).parent_path();
  nlohmann::json j = read_json(sidecar);
  const std::string tex = j["terms"][0]["texture"];
  REQUIRE(::mkfifo((folder / "fifo.exr").c_str(), 0600) == 0);
  fs::create_symlink("/dev/zero", folder / "zero.exr");
  fs::create_symlink("/dev/zero", d.path / "zero.csv");
  j["terms"][0]["texture"] = "fifo.exr";
  write_text((folder / "fifo_tex.json").string(), j.dump());
  j["terms"][0]["texture"] = "zero.exr";
  write_text((folder / "zero_tex.json").string(), j.dump());
  const Case cases[] = {
      {d / "pipe.csv", "expected a regular file, found a FIFO"},
      {d / "pipe.astm", "expected a regular file, found a FIFO"},
      {d / "pipe.brdf", "expected a regular file, found a FIFO"},
      {d / "pipe.json", "expected a regular file, found a FIFO"},
      {d / "folder.csv", "expected a regular file, found a directory"},
      {(folder / "fifo_tex.json").string(), "expected a regular file, found a FIFO"},
      {(folder / "zero_tex.json").string(), "not through a symbolic link"},
      {d / "zero.csv", "expected a regular file, found a character device"},
  };
  for (const Case& c : cases) {
    INFO(c.brdf);
    std::string out;
    // Bounded: before the fix these blocked forever (FIFO) or spun (/dev/zero).
    CHECK(run_cli_bounded({"eval", "--brdf", c.brdf, "--wi", "0,0,1", "--wo", "0,0,1"}, cli_log(d), 30, &out) == 2);
    INFO(out);
    CHECK_THAT(out, Contains(c.message));
    CHECK_THAT(out, Contains(fs::path(c.brdf).filename().string()) || Contains("texture"));
  }
  // A FIFO as a sampling file and as the config itself.
  REQUIRE(::mkfifo((d / "samples.csv").c_str(), 0600) == 0);
  const std::string cfg = write_text(d / "fifo_sampling.toml",
                                     "[experiment]\nname = \"t\"\n[[brdf]]\npreset = \"bluepaint\"\n[sampling]\n"
                                     "kind = \"file\"\npath = \"" + (d / "samples.csv") + "\"\n[[method]]\n"
                                     "kind = \"svd\"\nterms = 1\ntexture_size = 6\n");
  REQUIRE(::mkfifo((d / "cfg.toml").c_str(), 0600) == 0);
  for (const std::string& config : {cfg, d / "cfg.toml"}) {
    INFO(config);
    std::string out;
    const int rc = run_cli_bounded({"run", config, "--out", d / "o", "--no-plots", "-q"}, cli_log(d), 60, &out);
    INFO(out);
    CHECK(rc == 2);
    CHECK_THAT(out, Contains("expected a regular file, found a FIFO"));
  }
}

TEST_CASE("hostile files: sidecar texture names stay inside the sidecar's folder and say nothing about other files") {
  ScratchDir d;
  const std::string sidecar = exported_sidecar(d);
  REQUIRE(!sidecar.empty());
  const fs::path folder = fs::path(sidecar).parent_path();
  nlohmann::json j = read_json(sidecar);
  const std::string real = j["terms"][0]["texture"];
  // An existing texture outside the folder, reached by '..' and by an absolute path.
  fs::copy_file(folder / real, d.path / "outside.exr");
  const std::string rel_up = fs::relative(d.path / "outside.exr", folder).string();
  REQUIRE(rel_up.rfind("..", 0) == 0);
  const std::vector<std::pair<std::string, std::string>> names = {
      {rel_up, "../../../nowhere.exr"},
      {(d.path / "outside.exr").string(), (d.path / "nowhere.exr").string()},
      {"sub/../" + real, "sub/../missing.exr"},
      {"./" + real, "./missing.exr"},
  };
  for (const auto& [exists, missing] : names) {
    std::string msg[2];
    int k = 0;
    for (const std::string& name : {exists, missing}) {
      INFO(name);
      j["terms"][0]["texture"] = name;
      const std::string path = (folder / ("t" + std::to_string(k) + ".json")).string();
      write_text(path, j.dump());
      std::string err;
      CHECK(run_cli_stderr("eval --brdf " + path + " --wi 0,0,1 --wo 0,0,1", &err) == 2);
      INFO(err);
      CHECK_THAT(err, Contains("field 'terms[0].texture': expected a file name inside the sidecar's folder"));
      // The message with the file name removed: the same whether the file exists.
      const auto at = err.find(name);
      msg[k] = at == std::string::npos ? err : err.substr(0, at);
      msg[k] = msg[k].substr(msg[k].find(".json"));
      ++k;
    }
    CHECK(msg[0] == msg[1]);
  }
  // A symbolic link inside the folder to the texture outside it, and a linked subfolder.
  fs::create_symlink(d.path / "outside.exr", folder / "link.exr");
  fs::create_directory_symlink(d.path, folder / "linkdir");
  for (const std::string name : {"link.exr", "linkdir/outside.exr"}) {
    INFO(name);
    j["terms"][0]["texture"] = name;
    const std::string path = (folder / "t-link.json").string();
    write_text(path, j.dump());
    std::string err;
    CHECK(run_cli_stderr("eval --brdf " + path + " --wi 0,0,1 --wo 0,0,1", &err) == 2);
    INFO(err);
    CHECK_THAT(err, Contains("field 'terms[0].texture'") && Contains("not through a symbolic link"));
  }
}

TEST_CASE("hostile files: a sidecar cannot make the loader allocate without bound") {
  ScratchDir d;
  const std::string sidecar = exported_sidecar(d);
  REQUIRE(!sidecar.empty());
  const fs::path folder = fs::path(sidecar).parent_path();
  const nlohmann::json j = read_json(sidecar);
  SECTION("thousands of terms naming one texture") {
    nlohmann::json many = j;
    many["terms"] = nlohmann::json::array();
    for (int k = 0; k < 5000; ++k) many["terms"].push_back(j["terms"][0]);
    write_text((folder / "many.json").string(), many.dump());
    std::string out;
    CHECK(run_cli_bounded({"eval", "--brdf", (folder / "many.json").string(), "--wi", "0,0,1", "--wo", "0,0,1"},
                          cli_log(d), 30, &out, 1024) == 2);
    CHECK_THAT(out, Contains("many.json: field 'terms': expected at most 1024 terms, found 5000"));
  }
  SECTION("few terms of the largest resolution, counted before any texture is read") {
    nlohmann::json big = j;
    big["terms"] = nlohmann::json::array();
    for (int k = 0; k < 65; ++k) {
      nlohmann::json t = j["terms"][0];
      t["resolution"] = 1024;
      t.erase("mask_texels");
      big["terms"].push_back(t);
    }
    write_text((folder / "big.json").string(), big.dump());
    std::string out;
    CHECK(run_cli_bounded({"eval", "--brdf", (folder / "big.json").string(), "--wi", "0,0,1", "--wo", "0,0,1"},
                          cli_log(d), 30, &out, 1024) == 2);
    CHECK_THAT(out, Contains("field 'terms': expected at most 67108864 texels over all terms") &&
                        Contains("found 68157440 texels"));
  }
}

TEST_CASE("hostile configs: keys nested tens of thousands deep are refused before the TOML parser") {
  ScratchDir d;
  auto chain = [](int n, const char* sep) {
    std::string s = "a";
    for (int i = 1; i < n; ++i) s.append(sep).append("a");
    return s;
  };
  const int deep = 35000;  // about 70 KB, the size that crashed
  const std::vector<std::pair<std::string, std::string>> texts = {
      {"dotted key", chain(deep, ".") + " = 1\n"},
      {"table header", "[" + chain(deep, ".") + "]\n"},
      {"array-of-tables header", "[[" + chain(deep, ".") + "]]\n"},
      {"quoted parts", "[\"" + chain(deep, "\".\"") + "\"]\n"},
      {"spaced parts", chain(deep, " . ") + " = 1\n"},
      {"dotted key in inline table", "x = { " + chain(deep, ".") + " = 1 }\n"},
      {"dotted keys inside nested inline tables", [] {
         std::string s = "x = ";
         for (int i = 0; i < 200; ++i) s += "{ a.b.c = ";
         s += "1";
         for (int i = 0; i < 200; ++i) s += " }";
         return s + "\n";
       }()},
  };
  for (const auto& [what, text] : texts) {
    INFO(what);
    const std::string cfg = write_text(d / "deep.toml", text);
    std::string out;
    CHECK(run_cli_bounded({"run", cfg, "--dry-run"}, cli_log(d), 30, &out) == 2);
    INFO(out.substr(0, 300));
    CHECK_THAT(out, Contains("deep.toml:1: TOML: a key nests") && Contains("(limit 256)"));
  }
  // The same through -D (its value is parsed as TOML): taken as a string, no crash.
  const std::string ok = write_text(d / "ok.toml", std::string(kConfigHead) + "[[method]]\nkind = \"svd\"\n");
  std::string out;
  CHECK(run_cli_bounded({"run", ok, "--dry-run", "-D", "method.label={" + chain(deep, ".") + " = 1}"}, cli_log(d), 30,
                        &out) == 0);
  CHECK_THAT(out, Contains("would run 1"));
  // An ordinary config with dotted keys and inline tables still parses.
  CHECK(bf::toml_key_depth_problem("a.b.c = 1\n[x.y]\nz = { p.q = [1, {r = 2}] } # a.b.c.d\ns = \"a.b.c\"\n",
                                   "t.toml")
            .empty());
  CHECK(bf::toml_key_depth_problem(chain(256, ".") + " = 1\n", "t.toml").empty());
  CHECK_THAT(bf::toml_key_depth_problem(chain(257, ".") + " = 1\n", "t.toml"),
             Contains("t.toml:1: TOML: a key nests 257 tables deep"));
  // Depth adds up across headers and inline tables: 200 + 57 = 257.
  CHECK_THAT(bf::toml_key_depth_problem("[" + chain(200, ".") + "]\nx = 1\n" + chain(57, ".") + " = 2\n", "t.toml"),
             Contains("t.toml:3: TOML: a key nests 257 tables deep"));
  CHECK(bf::toml_key_depth_problem("[" + chain(200, ".") + "]\n" + chain(56, ".") + " = 2\n", "t.toml").empty());
  // Nested arrays alone stay toml++'s to refuse (TOML_MAX_NESTED_VALUES).
  CHECK(bf::toml_key_depth_problem("x = " + std::string(1000, '[') + std::string(1000, ']') + "\n", "t.toml").empty());
}

TEST_CASE("hostile configs: the run count is checked before the plan is built") {
  ScratchDir d;
  auto list = [](int n) {
    std::string s = "[";
    for (int i = 0; i < n; ++i) s += (i ? ", " : "") + std::to_string(0.001 * (i + 1));
    return s + "]";
  };
  // 10 samplings x 100,000 method variants = 10^6 runs; 10^7 with 100 samplings.
  for (int samplings : {10, 100}) {
    std::string text = "[experiment]\nname = \"big\"\n[[brdf]]\npreset = \"bluepaint\"\n";
    for (int s = 0; s < samplings; ++s) text += "[[sampling]]\nkind = \"stratified\"\ncount = " + std::to_string(1000 + s) + "\n";
    text += "[[method]]\nkind = \"fit\"\nprojections = [{ name = \"wi\" }, { name = \"h\" }]\nsmoothing = " +
            list(1000) + "\neps = " + list(100) + "\n";
    const std::string cfg = write_text(d / "big.toml", text);
    std::string out;
    const auto t0 = std::chrono::steady_clock::now();
    // 1 GB of address space: the old planner needed 3.6 GB for 10^6 runs.
    CHECK(run_cli_bounded({"run", cfg, "--dry-run"}, cli_log(d), 60, &out, 1024) == 2);
    INFO(out);
    CHECK_THAT(out, Contains("big.toml: experiment: the config expands to more than 100000 runs") &&
                        Contains(std::to_string(samplings) + " sampling x 100000 method"));
    CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(30));
  }
}

TEST_CASE("hostile configs: names read from a config cannot climb out of the output folder") {
  for (const char* name : {"..", ".", "a/b", "../x"}) {
    INFO(name);
    const auto errs = config_errors(std::string("[experiment]\nname = \"") + name + "\"\n" +
                                    "[[brdf]]\npreset = \"bluepaint\"\n[sampling]\nkind = \"grid\"\n"
                                    "resolution = 6\n[[method]]\nkind = \"svd\"\n");
    REQUIRE(errs.size() == 1);
    CHECK_THAT(errs[0], Contains("cfg.toml:2: experiment.name: expected a non-empty name"));
  }
  CHECK(bf::is_plain_name("quickstart-2.b_c"));
  CHECK_FALSE(bf::is_plain_name(".."));
  CHECK_FALSE(bf::is_plain_name(std::string("a\0b", 3)));
  CHECK(bf::is_path_inside("runs/abc/run.json"));
  CHECK_FALSE(bf::is_path_inside("runs/../../x"));
  CHECK_FALSE(bf::is_path_inside("/etc/passwd"));
  CHECK_FALSE(bf::is_path_inside("runs//x"));
}

TEST_CASE("hostile options: unbounded sizes and negative seeds or members are refused by name") {
  ScratchDir d;
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::string strat = write_text(d / "strat.toml", std::string("[experiment]\nname = \"t\"\n[[brdf]]\n") +
                                                             "preset = \"bluepaint\"\n[sampling]\nkind = "
                                                             "\"stratified\"\ncount = 100000000\n[[method]]\n"
                                                             "kind = \"svd\"\n");
  const std::string grid = write_text(d / "grid.toml", std::string("[experiment]\nname = \"t\"\n[[brdf]]\n") +
                                                           "preset = \"bluepaint\"\n[sampling]\nkind = \"grid\"\n"
                                                           "resolution = 256\n[[method]]\nkind = \"svd\"\n");
  const Case cases[] = {
      {{"bench", "fit", "--terms", "100000"}, "--terms: expected 1..1024, found 100000"},
      {{"bench", "fit", "--terms", "1024", "--texture", "1024"}, "--terms x --texture^2: expected at most 67108864"},
      {{"bench", "fit", "--samples", "100000000"}, "--samples: expected 0..10000000, found 100000000"},
      {{"bench", "search", "--terms", "100000"}, "terms: expected 1..64, found 100000"},
      {{"bench", "search", "--restarts", "100000000"}, "restarts: expected 0..100000, found 100000000"},
      {{"bench", "lines", "--starts", "100000000"}, "--starts: expected 1..10000, found 100000000"},
      {{"bench", "lines", "--texture", "100000"}, "texture_size: expected 2..1024, found 100000"},
      {{"sample", "--brdf", "bluepaint", "--out", d / "s.csv", "--stratified", "100000000"},
       "stratified count: expected 1..10000000"},
      {{"sample", "--brdf", "bluepaint", "--out", d / "s.csv", "--grid", "200"}, "grid resolution: expected 2..64"},
      // A negative seed is refused by name (CLI11 2.1 alone would wrap it to 2^64 - 1).
      {{"bench", "search", "--seed", "-1"}, "--seed: expected a non-negative integer, found -1"},
      {{"bench", "planted", "--seed", "-3"}, "--seed: expected a non-negative integer, found -3"},
      {{"compare", "--brdf", "bluepaint", "--reference", "bluepaint", "--seed", "-1"},
       "--seed: expected a non-negative integer, found -1"},
      {{"sample", "--brdf", "bluepaint", "--out", d / "s.csv", "--stratified", "10", "--seed", "-1"},
       "--seed: expected a non-negative integer, found -1"},
      {{"bench", "planted", "--first", "-1"}, "--first: expected a member index >= 0, found -1"},
      {{"bench", "planted", "--count", "0"}, "--count: expected >= 1"},
      {{"bench", "planted", "--grid", "1"}, "--grid: expected 2..64, found 1"},
      {{"bench", "planted", "--texture", "4096"}, "--texture: expected 2..1024, found 4096"},
      // The searches' own options, checked (SearchOptions::validate) before any member's fits.
      {{"bench", "planted", "--keep", "0"}, "keep: expected >= 1, found 0"},
      {{"run", strat, "--dry-run"}, "sampling.count: expected an integer in 1..10000000, found 100000000"},
      {{"run", grid, "--dry-run"}, "sampling.resolution: expected an integer in 2..64, found"},
  };
  for (const Case& c : cases) {
    std::string cmd;
    for (const auto& a : c.args) cmd += a + " ";
    INFO(cmd);
    std::string out;
    // 2 GB of address space and 60 s: a refusal, not an allocation.
    CHECK(run_cli_bounded(c.args, cli_log(d), 60, &out, 2048) == 2);
    INFO(out);
    CHECK_THAT(out, Contains(c.message));
    CHECK_THAT(out, !Contains("bad_alloc"));
    CHECK_THAT(out, !Contains("|---|"));  // refused before any table is printed
  }
}

TEST_CASE("hostile values: eval never prints inf or nan, and number messages say what was wrong") {
  ScratchDir d;
  // Parameters validation accepts whose value overflows double arithmetic.
  for (const char* spec : {"cook-torrance:m=1e-200", "ward:ax=1e-170,ay=1e-170", "blinn-phong:n=1e300",
                           "cook-torrance:m=1e-320", "ward:ax=1e-320,ay=1e-320"}) {
    INFO(spec);
    for (const char* dirs : {"--wi 0,0,1 --wo 0,0,1", "--wi 0.3,0.1,1 --wo -0.3,-0.1,1", "--wi 1,0,0.01 --wo 0,1,0.01"}) {
      INFO(dirs);
      std::string text;
      const int rc = run_cli(std::string("eval --brdf ") + spec + " " + dirs, &text);
      INFO(text);
      CHECK((rc == 0 || rc == 2));
      if (rc == 0) {
        std::istringstream in(text);
        double v[3] = {-1, -1, -1};
        in >> v[0] >> v[1] >> v[2];
        CHECK(!in.fail());
        for (double x : v) CHECK(std::isfinite(x));
      } else {
        CHECK_THAT(text, Contains("expected a finite value") || Contains(spec));
      }
      CHECK_THAT(text, !Contains("expects one number") && !Contains("stoi"));
    }
  }
  // Measured values near the top of double: no inf printed.
  std::string csv = "theta_i,phi_i,theta_o,phi_o,r,g,b\n";
  for (int i = 0; i < 40; ++i)
    csv += std::to_string(0.02 * i) + ",0.1," + std::to_string(0.02 * i) + ",3.2,1e300,1.7e308,1e308\n";
  write_text(d / "huge.csv", csv);
  std::string text;
  const int rc = run_cli("eval --brdf " + (d / "huge.csv") + " --wi 0,0,1 --wo 0,0,1", &text);
  INFO(text);
  CHECK((rc == 0 || rc == 2));
  CHECK_THAT(text, !Contains("inf") && !Contains("nan"));
  // Denormal directions are numbers, and -D indices too large say so instead of "stoi".
  CHECK(run_cli("eval --brdf lambert --wi 1e-320,0,1 --wo 0,0,1", &text) == 0);
  const std::string ok = write_text(d / "ok.toml", std::string(kConfigHead) + "[[method]]\nkind = \"svd\"\n");
  CHECK(run_cli("run " + ok + " --dry-run -D method[99999999999].terms=1", &text) == 2);
  CHECK_THAT(text, Contains("expected section.key") && !Contains("stoi"));
  // A -D integer beyond 64 bits is refused as one, not read as the string "99...9".
  for (const char* def : {"experiment.seed=99999999999999999999999", "method.terms=-18446744073709551617"}) {
    INFO(def);
    CHECK(run_cli("run " + ok + " --dry-run -D " + def, &text) == 2);
    CHECK_THAT(text, Contains(std::string(def).substr(0, std::string(def).find('='))) &&
                         Contains("expected an integer in 64 bits") && !Contains("(a string)"));
  }
}

TEST_CASE("hostile values: log-space messages tell overflow from an all-zero BRDF") {
  bf::SampleSet s;
  for (int k = 0; k < 10; ++k) s.push(bf::Vec3(0, 0, 1), bf::Vec3(0, 0, 1), bf::Rgb(1.7e308, 1.0, 1.0), 1.0);
  // Values near the top of double: the mean is summed without overflow (it
  // used to overflow to inf and be reported as "an all-zero BRDF").
  const bf::LogTransform t = bf::LogTransform::of(s, 1e-5);
  CHECK(t.A[0] == Approx(1.7e308));
  CHECK(std::isfinite(t.A[0]));
  bf::SampleSet z;
  for (int k = 0; k < 10; ++k) z.push(bf::Vec3(0, 0, 1), bf::Vec3(0, 0, 1), bf::Rgb(1.0, 1.0, 0.0), 1.0);
  CHECK_THROWS_WITH(bf::LogTransform::of(z, 1e-5), Contains("channel b has mean 0") && Contains("all-zero"));
  bf::SampleSet tiny;  // denormal values are accepted (the stress case "denormal")
  for (int k = 0; k < 10; ++k) tiny.push(bf::Vec3(0, 0, 1), bf::Vec3(0, 0, 1), bf::Rgb(1e-310, 1e-310, 1e-310), 1.0);
  CHECK(bf::LogTransform::of(tiny, 1e-5).A[0] > 0);
}
