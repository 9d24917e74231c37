// Whether the plot step of write_experiment_outputs (outputs.h) failed. The
// plot script's stderr is kept in DIR/plots.log only when it failed (exit
// status not 0); `run` and `merge` then exit 2 after writing every table.
#pragma once

#include <string>

#include "experiments/report/outputs.h"

namespace bf {

// "" when the plot step did not fail (plots drawn, not requested, no
// python3 with matplotlib, no usable rows), else one line: "plots: <script>
// failed (exit status N): <the last line of its output> (its output:
// plots.log); the tables are written: DIR/results.md".
std::string plot_failure(const OutputFiles& f);

}  // namespace bf
