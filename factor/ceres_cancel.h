// A Ceres iteration callback that ends a solve when a cancellation was
// requested (solvers/cancel.h); after ceres::Solve, check_cancel() turns the
// aborted solve into bf::Cancelled.
#pragma once

#include <ceres/iteration_callback.h>

#include "solvers/cancel.h"

namespace bf {

class CeresCancelCallback final : public ceres::IterationCallback {
 public:
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return cancel_requested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
};

}  // namespace bf
