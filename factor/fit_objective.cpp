// The homomorphic fit's objective at a solution, sample by sample
// (factor/fit_internal.h).
#include <vector>

#include "factor/fit_internal.h"

namespace bf::fit {

double sample_rel_mse(const FitData& d, const std::array<std::vector<double>, 3>& fixed_values,
                      const JointSystem& sys, const Eigen::MatrixXd& Y, const FitOptions& opt, bool exact_error) {
  const size_t N = d.size();
  std::vector<int> idx(8 * sys.terms.size());
  std::vector<double> val(8 * sys.terms.size());
  double se = 0;
  for (size_t k = 0; k < N; ++k) {
    const int L = stencil(sys, k, idx.data(), val.data());
    for (int c = 0; c < 3; ++c) {
      double s = fixed_values[c][k];
      for (int a = 0; a < L; ++a) s += val[a] * Y(idx[a], c);
      const double e =
          (exact_error ? model_log_value(d.clamp_log(c, s, opt), opt) : s) - d.g[c][k];
      se += d.w[k] * e * e;
    }
  }
  return se / (3.0 * d.W);
}

}  // namespace bf::fit
