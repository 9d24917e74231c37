// The joint fit's linear solver: which path solves the normal equations
// (FitOptions::Solver) for a system of a given size.
//
// Auto picks the dense path (dense normal matrix, staircase Cholesky) for
// small systems and the sparse path (column-by-column assembly, sparse
// Cholesky) for large ones. The dense path's cost grows with the cube of the
// unknowns, the sparse assembly's with the samples, so the crossover moves up
// with many samples. The thresholds are measured crossovers (docs/speed.md,
// "Dense against sparse").
#pragma once

#include <cstddef>

#include "factor/homomorphic_fit.h"

namespace bf {

// Auto solves dense up to this many unknowns ...
inline constexpr size_t kDenseMaxUnknowns = 1650;
// ... or up to this many with at least kManySamples valid samples.
inline constexpr size_t kDenseMaxUnknownsManySamples = 2200;
inline constexpr size_t kManySamples = 500000;

// The path that solves a system of `unknowns` texels fitted to `samples` valid
// samples: `requested` itself unless it is Auto (an explicit choice, including
// ReferenceQR, is never overridden); for Auto, Dense when unknowns <= the
// threshold above for that many samples, else Sparse. Never returns Auto.
FitOptions::Solver choose_linear_solver(FitOptions::Solver requested, size_t unknowns, size_t samples);

}  // namespace bf
