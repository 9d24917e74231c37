// `merge` copies only the regular files a shard's runs list, never follows a
// link out of a shard, and leaves no half-written merged folder
// (docs/robustness.md "merge: links and special files in shard folders").
// Each case plants one thing in a shard folder, runs the real CLI, and checks
// the refusal names the planted path and the output folder is absent (new)
// or byte for byte as it was (a previous merge).
#include <sys/stat.h>
#include <sys/types.h>

#include <catch2/catch.hpp>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>

#include "experiments_helpers.h"
#include "process_helpers.h"

using namespace bf_test;
using Catch::Matchers::Contains;

namespace {

// Every entry under dir (relative path -> bytes for files, "<dir>" for folders,
// "-> target" for links), not following links.
void snapshot_into(const fs::path& root, const fs::path& dir, std::map<std::string, std::string>& s) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::path p = it->path();
    const std::string rel = p.lexically_relative(root).string();
    const auto st = fs::symlink_status(p, ec);
    if (fs::is_symlink(st)) {
      s[rel] = "-> " + fs::read_symlink(p, ec).string();
    } else if (fs::is_directory(st)) {
      s[rel] = "<dir>";
      snapshot_into(root, p, s);
    } else if (fs::is_regular_file(st)) {
      s[rel] = read_text(p.string());
    } else {
      s[rel] = "<other>";
    }
  }
}

std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> s;
  std::error_code ec;
  if (fs::is_directory(fs::symlink_status(dir, ec))) snapshot_into(dir, dir, s);
  return s;
}

std::string merge_cli(const std::vector<std::string>& dirs, const fs::path& out, int* code) {
  std::vector<std::string> args = {"merge"};
  for (const auto& d : dirs) args.push_back(d);
  for (const char* a : {"--out", "", "--no-plots", "-q"}) args.push_back(a);
  args[args.size() - 3] = out.string();
  std::string text;
  *code = run_cli_bounded(args, out.string() + ".log", 120, &text);
  return text;
}

struct Shards {
  ScratchDir d;
  std::string s1, s2;
  std::string first_run;  // a run of shard 1
  Shards() {
    // The two shards are computed once per process and copied for each case.
    static ScratchDir made;
    static const bool ran = [] {
      const std::string cfg = write_text(made / "tiny.toml", kTinyConfig);
      run_quiet(cfg, made / "s1", {}, false, false, 1, 2);
      run_quiet(cfg, made / "s2", {}, false, false, 2, 2);
      return true;
    }();
    (void)ran;
    s1 = d / "s1";
    s2 = d / "s2";
    fs::copy(made.path / "s1", s1, fs::copy_options::recursive);
    fs::copy(made.path / "s2", s2, fs::copy_options::recursive);
    const auto m = nlohmann::json::parse(read_text(s1 + "/manifest.json"));
    first_run = m["runs"][0]["run_id"];
    write_text(d / "outside/secret.txt", "secret outside the shard\n");
    write_text(d / "outside/dir/inner.txt", "inner\n");
  }
  fs::path run_dir() const { return fs::path(s1) / "runs" / first_run; }
};

}  // namespace

TEST_CASE("merge links: links, loops and special files in a shard are refused, naming them, writing nothing") {
  // What each case plants, and the path the message must name.
  const std::vector<std::pair<std::string, std::function<fs::path(Shards&)>>> plants = {
      {"an extra link to a file outside the shard",
       [](Shards& s) {
         fs::create_symlink(s.d.path / "outside/secret.txt", s.run_dir() / "notes.txt");
         return s.run_dir() / "notes.txt";
       }},
      {"a listed file replaced by a link to a file outside the shard",
       [](Shards& s) {
         fs::remove(s.run_dir() / "sphere.png");
         fs::create_symlink(s.d.path / "outside/secret.txt", s.run_dir() / "sphere.png");
         return s.run_dir() / "sphere.png";
       }},
      {"a link to a folder outside the shard",
       [](Shards& s) {
         fs::create_directory_symlink(s.d.path / "outside/dir", s.run_dir() / "more");
         return s.run_dir() / "more";
       }},
      {"a link loop",
       [](Shards& s) {
         fs::create_symlink(s.run_dir() / "loop-b", s.run_dir() / "loop-a");
         fs::create_symlink(s.run_dir() / "loop-a", s.run_dir() / "loop-b");
         return s.run_dir() / "loop-";  // either link may be named first
       }},
      {"a link to the run's own folder",
       [](Shards& s) {
         fs::create_directory_symlink(s.run_dir(), s.run_dir() / "self");
         return s.run_dir() / "self";
       }},
      {"a run folder that is a link",
       [](Shards& s) {
         const fs::path moved = s.d.path / "outside/moved-run";
         fs::rename(s.run_dir(), moved);
         fs::create_directory_symlink(moved, s.run_dir());
         return s.run_dir();
       }},
      {"a runs folder that is a link",
       [](Shards& s) {
         const fs::path moved = s.d.path / "outside/moved-runs";
         fs::rename(fs::path(s.s1) / "runs", moved);
         fs::create_directory_symlink(moved, fs::path(s.s1) / "runs");
         return fs::path(s.s1) / "runs";
       }},
      {"a FIFO",
       [](Shards& s) {
         REQUIRE(::mkfifo((s.run_dir() / "pipe").c_str(), 0644) == 0);
         return s.run_dir() / "pipe";
       }},
      {"a subfolder",
       [](Shards& s) {
         write_text((s.run_dir() / "sub/x.txt").string(), "x");
         return s.run_dir() / "sub";
       }},
  };
  for (const auto& [what, plant] : plants) {
    INFO(what);
    Shards s;
    // A previous merge of the honest shards, which a refused merge must leave as it was.
    const fs::path previous = s.d.path / "previous";
    int code = 0;
    std::string text = merge_cli({s.s1, s.s2}, previous, &code);
    REQUIRE(code == 0);
    const auto before = snapshot(previous);
    REQUIRE(!before.empty());

    const fs::path planted = plant(s);
    const fs::path fresh = s.d.path / "merged";
    text = merge_cli({s.s1, s.s2}, fresh, &code);
    INFO(text);
    CHECK(code == 2);
    CHECK_THAT(text, Contains(planted.string()));
    CHECK(!fs::exists(fs::symlink_status(fresh)));
    text = merge_cli({s.s1, s.s2}, previous, &code);
    INFO(text);
    CHECK(code == 2);
    CHECK_THAT(text, Contains(planted.string()));
    CHECK(snapshot(previous) == before);
    // Nothing from outside reached any output.
    for (const auto& [rel, bytes] : snapshot(s.d.path)) {
      if (rel.rfind("outside", 0) == 0) continue;
      INFO(rel);
      CHECK(bytes.find("secret outside the shard") == std::string::npos);
    }
  }
}

TEST_CASE("merge links: an honest merge copies exactly the files each run lists") {
  Shards s;
  // An unlisted regular file in a run folder is not copied (only expected files are).
  write_text((s.run_dir() / "stray.txt").string(), "stray");
  const fs::path out = s.d.path / "merged";
  int code = 0;
  const std::string text = merge_cli({s.s1, s.s2}, out, &code);
  INFO(text);
  REQUIRE(code == 0);
  CHECK(!fs::exists(out / "runs" / s.first_run / "stray.txt"));
  const auto rec = nlohmann::json::parse(read_text((s.run_dir() / "run.json").string()));
  for (const auto& f : rec["files"]) {
    INFO(f.get<std::string>());
    CHECK(fs::is_regular_file(fs::symlink_status(out / f.get<std::string>())));
    CHECK(read_text((out / f.get<std::string>()).string()) == read_text((fs::path(s.s1) / f.get<std::string>()).string()));
  }
  CHECK(fs::exists(out / "runs" / s.first_run / "DONE"));
  // No staging folder is left next to the output.
  for (const auto& e : fs::directory_iterator(s.d.path)) {
    INFO(e.path().string());
    CHECK(e.path().filename().string().find(".merge-") == std::string::npos);
  }
}

TEST_CASE("merge links: a shard run whose files fail verification is refused, naming the file") {
  Shards s;
  // One byte of a listed file changed after the shard finished.
  std::string b = read_text((s.run_dir() / "run.json").string());
  const size_t at = b.find("\"rel_mse\": \"");
  REQUIRE(at != std::string::npos);
  b[at + 13] = b[at + 13] == '1' ? '2' : '1';
  std::ofstream((s.run_dir() / "run.json").string(), std::ios::binary | std::ios::trunc) << b;
  const fs::path out = s.d.path / "merged";
  int code = 0;
  const std::string text = merge_cli({s.s1, s.s2}, out, &code);
  INFO(text);
  CHECK(code == 2);
  CHECK_THAT(text, Contains((s.run_dir() / "run.json").string()) && Contains("content hash"));
  CHECK(!fs::exists(out));
}
