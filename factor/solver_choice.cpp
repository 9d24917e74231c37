#include "factor/solver_choice.h"

namespace bf {

FitOptions::Solver choose_linear_solver(FitOptions::Solver requested, size_t unknowns, size_t samples) {
  if (requested != FitOptions::Solver::Auto) return requested;
  const size_t dense_max = samples >= kManySamples ? kDenseMaxUnknownsManySamples : kDenseMaxUnknowns;
  return unknowns <= dense_max ? FitOptions::Solver::Dense : FitOptions::Solver::Sparse;
}

}  // namespace bf
