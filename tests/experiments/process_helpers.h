// Child processes for the robustness tests: the real CLI started with
// fork/exec, with an address-space limit if asked, and every wait bounded so
// that a regression (a hang, a blocked read) fails the test instead of hanging it.
#pragma once

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace bf_test {

struct Child {
  pid_t pid = -1;
  int status = 0;
  bool exited = false;  // reaped
};

// Starts BF_CLI_PATH with `args`; stdout and stderr go to `log`. as_limit_mb > 0
// caps the child's address space (RLIMIT_AS), so unbounded allocation fails fast.
inline Child spawn_cli(const std::vector<std::string>& args, const std::string& log, long as_limit_mb = 0) {
  Child c;
  c.pid = ::fork();
  if (c.pid == 0) {
    std::FILE* f = std::freopen(log.c_str(), "w", stderr);
    if (f) ::dup2(::fileno(stderr), 1);
    if (as_limit_mb > 0) {
#if defined(__SANITIZE_ADDRESS__)
      // AddressSanitizer reserves terabytes of shadow address space, so an
      // address-space limit stops it from starting: bound the allocation
      // sizes and the resident memory through its own options instead.
      const char* prev = std::getenv("ASAN_OPTIONS");
      const std::string opts = std::string(prev ? prev : "") + ":allocator_may_return_null=1:max_allocation_size_mb=" +
                               std::to_string(as_limit_mb) + ":hard_rss_limit_mb=" + std::to_string(2 * as_limit_mb);
      ::setenv("ASAN_OPTIONS", opts.c_str(), 1);
#else
      struct rlimit rl;
      rl.rlim_cur = rl.rlim_max = static_cast<rlim_t>(as_limit_mb) << 20;
      ::setrlimit(RLIMIT_AS, &rl);
#endif
    }
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(BF_CLI_PATH));
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(BF_CLI_PATH, argv.data());
    std::_Exit(127);
  }
  return c;
}

// Waits at most `seconds` for the child; true if it ended (status in c.status).
inline bool wait_child(Child& c, double seconds) {
  if (c.exited) return true;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(c.pid, &c.status, WNOHANG) == c.pid) {
      c.exited = true;
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

// Kills and reaps a child still running (cleanup after a failed wait).
inline void kill_child(Child& c) {
  if (c.pid > 0 && !c.exited) {
    ::kill(c.pid, SIGKILL);
    ::waitpid(c.pid, &c.status, 0);
    c.exited = true;
  }
}

// Exit code, or -1 for a crash / signal.
inline int exit_code(const Child& c) { return WIFEXITED(c.status) ? WEXITSTATUS(c.status) : -1; }

// Runs the CLI to completion within `seconds` (killed after, returning -2),
// output into *out.
inline int run_cli_bounded(const std::vector<std::string>& args, const std::string& log, double seconds,
                           std::string* out, long as_limit_mb = 0) {
  Child c = spawn_cli(args, log, as_limit_mb);
  const bool ended = wait_child(c, seconds);
  if (!ended) kill_child(c);
  if (out) {
    std::FILE* f = std::fopen(log.c_str(), "rb");
    out->clear();
    if (f) {
      char buf[4096];
      size_t n;
      while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) out->append(buf, n);
      std::fclose(f);
    }
  }
  return ended ? exit_code(c) : -2;
}

}  // namespace bf_test
