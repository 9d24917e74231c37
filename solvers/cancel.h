// Cooperative cancellation of long computations (fits, searches, tabulations,
// Ceres solves): one process-wide request, polled at cancellation points
// inside their loops. The library never requests a cancellation itself; a
// caller that can be interrupted does (the Python module on Ctrl-C, the
// runner when asked to by RunOptions::cancel_on_signal), and clears it again.
// A cancelled computation throws Cancelled from its next cancellation point
// and leaves no partial result.
#pragma once

#include <atomic>
#include <exception>

namespace bf {

// Thrown by check_cancel(). Deliberately not a std::runtime_error: code that
// recovers from a failed step (a refinement that failed keeps the fit) must
// not swallow a cancellation.
class Cancelled : public std::exception {
 public:
  const char* what() const noexcept override { return "cancelled"; }
};

// Asks every computation in progress to stop at its next cancellation point.
// Async-signal-safe (one lock-free atomic store): callable from a signal handler.
void request_cancel() noexcept;
// Withdraws the request (before starting new work).
void clear_cancel() noexcept;
bool cancel_requested() noexcept;

// A cancellation point: throws Cancelled when a cancellation was requested.
// Costs one relaxed atomic load; place it where a loop iteration takes well
// over a microsecond.
void check_cancel();

}  // namespace bf
