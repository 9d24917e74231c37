// Splits a sample set into the samples a fit sees and the ones held out of it
// (the single held-out fraction, validation.cpp, and each k-fold split,
// experiments/run/folds.cpp, share it).
#pragma once

#include <cstdint>
#include <vector>

#include "experiments/report/validation.h"

namespace bf {

// train: every sample of s whose held[k] is 0; held: the others. Order,
// validity, weights (when s has them) and symmetries are kept; the train set
// keeps s's invalid_* counts. Descriptions are left to the caller.
HoldoutSplit partition_held(const SampleSet& s, const std::vector<uint8_t>& held);

}  // namespace bf
