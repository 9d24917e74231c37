// Small helpers shared by the tests.
#pragma once

#include <catch2/catch.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "brdfs/brdf.h"

namespace bf_test {

// |a - b| <= tol * max(1, |a|, |b|)
inline bool near_rel(double a, double b, double tol) {
  return std::abs(a - b) <= tol * std::max({1.0, std::abs(a), std::abs(b)});
}

inline std::string str(const bf::Vec3& v) {
  return "(" + std::to_string(v.x()) + ", " + std::to_string(v.y()) + ", " +
         std::to_string(v.z()) + ")";
}

// A fresh folder under the system temp dir, removed at scope exit.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& tag) {
    static int counter = 0;
    path = std::filesystem::temp_directory_path() /
           ("bf_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
  // Writes `text` to the file `name` in the folder and returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(path / name) << text;
    return file(name);
  }
};

// The whole file as bytes ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

#ifdef BF_CLI_PATH
// Runs the brdf-factor CLI with `args` (stdout discarded); returns its exit
// code (-1 when it did not exit normally, e.g. a crash), stderr into *err.
inline int run_cli_stderr(const std::string& args, std::string* err) {
  TempDir d("cli");
  const std::string errfile = d.file("stderr.txt");
  // Appended piecewise: GCC 12 warns (-Wrestrict, a false positive) on a chain of +.
  std::string cmd = BF_CLI_PATH;
  cmd.append(" ").append(args).append(" > /dev/null 2> ").append(errfile);
  const int status = std::system(cmd.c_str());
  if (err) *err = slurp(errfile);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
#endif

// True when running under CI (the variable CI set to anything but "" / "false" / "0").
inline bool in_ci() {
  const char* ci = std::getenv("CI");
  if (ci == nullptr) return false;
  const std::string v = ci;
  return !v.empty() && v != "false" && v != "0";
}

// For a prerequisite that is not installed by scripts/install-deps.sh on every
// machine (a git checkout): missing in CI fails the test; elsewhere it warns
// and returns true so the caller returns. Prerequisites that install-deps.sh
// installs are REQUIREd outright instead.
inline bool skip_unless_ci(bool have, const std::string& what) {
  if (have) return false;
  if (in_ci()) FAIL(what << " (required under CI)");
  WARN(what << ": skipped (outside CI)");
  return true;
}

}  // namespace bf_test
