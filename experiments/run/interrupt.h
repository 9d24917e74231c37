// SIGINT / SIGTERM during `run` (docs/robustness.md): the first signal asks the
// runner to stop cleanly (no new run starts, the tables of the finished runs
// are written, a message says how to resume, exit 128 + signal); a second one
// kills the process at once (the default action).
#pragma once

#include <stdexcept>
#include <string>

namespace bf {

// Installs the handlers for its lifetime (restoring the previous ones after).
// cancel_work: the first signal also requests the cancellation of the
// computations in progress (solvers/cancel.h); the request is withdrawn when
// the scope ends.
class InterruptScope {
 public:
  explicit InterruptScope(bool cancel_work = false);
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
};

// The signal received since the scope was entered (SIGINT, SIGTERM), or 0.
int interrupt_signal();

// Test hook for the race between a finishing run and a signal (docs/robustness.md
// "Interrupt race"). With the environment variable BF_TEST_SIGNAL_AT_RUN_END
// set, the first call raises SIGINT and then waits, at most 10 s, until
// note_finished_runs_taken() is called; every other call returns at once. The
// runner calls it when a run's files are written, before its DONE marker.
void test_signal_at_run_end();
// The runner has taken its list of finished runs after a signal (releases the hook).
void note_finished_runs_taken();

// "SIGINT", "SIGTERM" or "signal N".
std::string signal_name(int sig);

// Thrown by the runner after it stopped cleanly on a signal; main exits with
// 128 + signal.
class Interrupted : public std::runtime_error {
 public:
  Interrupted(const std::string& what, int sig) : std::runtime_error(what), signal_(sig) {}
  int signal() const { return signal_; }

 private:
  int signal_;
};

}  // namespace bf
