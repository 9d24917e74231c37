// Signal handling for `run` (see interrupt.h).
#include "experiments/run/interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <thread>

#include "solvers/cancel.h"

namespace bf {

namespace {

std::atomic<int> g_signal{0};
std::atomic<bool> g_cancel_work{false};
struct sigaction g_old_int, g_old_term;

extern "C" void on_signal(int sig) {
  int expected = 0;
  if (g_signal.compare_exchange_strong(expected, sig)) {
    if (g_cancel_work.load()) request_cancel();
    static const char msg[] =
        "brdf-factor: interrupted: no new run starts; writing the finished runs (signal again to stop at once)\n";
    const ssize_t w = ::write(STDERR_FILENO, msg, sizeof msg - 1);
    (void)w;
    return;
  }
  // Second signal: the default action, now.
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

InterruptScope::InterruptScope(bool cancel_work) {
  g_signal = 0;
  g_cancel_work = cancel_work;
  if (cancel_work) clear_cancel();
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &sa, &g_old_int);
  ::sigaction(SIGTERM, &sa, &g_old_term);
}

InterruptScope::~InterruptScope() {
  ::sigaction(SIGINT, &g_old_int, nullptr);
  ::sigaction(SIGTERM, &g_old_term, nullptr);
  if (g_cancel_work.exchange(false)) clear_cancel();
}

int interrupt_signal() { return g_signal.load(); }

namespace {
std::atomic<bool> g_hook_fired{false};
std::atomic<bool> g_runs_taken{false};
}  // namespace

void test_signal_at_run_end() {
  static const bool enabled = std::getenv("BF_TEST_SIGNAL_AT_RUN_END") != nullptr;
  if (!enabled || g_hook_fired.exchange(true)) return;
  ::raise(SIGINT);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!g_runs_taken.load() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void note_finished_runs_taken() { g_runs_taken = true; }

std::string signal_name(int sig) {
  if (sig == SIGINT) return "SIGINT";
  if (sig == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(sig);
}

}  // namespace bf
