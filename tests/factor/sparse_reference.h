// The sparse fit's normal equations by the simple triplet assembly, the
// reference bf::sparse_normal_equations (column by column) is compared with.
#pragma once

#include <vector>

#include "factor/homomorphic_fit.h"

namespace bf_test {

// As bf::sparse_normal_equations: equal to it up to summation order.
bf::SparseNormal reference_sparse_normal_equations(const bf::FitData& d, const std::vector<bf::TermSpec>& joint,
                                                   const bf::FitOptions& opt);

}  // namespace bf_test
