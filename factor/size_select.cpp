// Tolerance-driven resolution and term count of homomorphic fits (see size_select.h).
#include "factor/size_select.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bf {

std::vector<TermSpec> terms_at_resolution(std::vector<TermSpec> terms, int res) {
  for (auto& t : terms) t.proj.res = res;
  return terms;
}

SizeChoice select_homomorphic_size(const FitData& data, const SampleSet& samples, const LogTransform& lt,
                                   const std::function<std::vector<TermSpec>(int res)>& terms_at,
                                   int min_terms, int max_terms, const FitOptions& opt,
                                   const std::string& method, const Tolerance& tol,
                                   const std::vector<int>& ladder) {
  validate_texture_ladder(ladder, 2, 1024, method + ": texture_ladder");
  tol.validate();
  if (min_terms < 1 || max_terms < min_terms)
    throw std::invalid_argument(method + ": terms: expected 1 <= min_terms <= max_terms, found " +
                                std::to_string(min_terms) + ".." + std::to_string(max_terms));
  const auto t0 = std::chrono::steady_clock::now();
  SizeChoice ch;
  ch.method = method;
  ch.knob = "terms";
  ch.metric = tol.metric;
  ch.error = std::numeric_limits<double>::infinity();
  for (int res : ladder) {
    const std::vector<TermSpec> all = terms_at(res);
    if (int(all.size()) < max_terms)
      throw std::invalid_argument(method + ": " + std::to_string(max_terms) + " terms asked for, only " +
                                  std::to_string(all.size()) + " projections given");
    for (int j = min_terms; j <= max_terms; ++j) {
      std::vector<double> errs;
      auto h = fit_homomorphic(data, std::vector<TermSpec>(all.begin(), all.begin() + j), opt, method, &errs);
      const double e = tol.error_of(*h, samples, lt);
      ch.tried.push_back({j, -1, e, res});
      const bool reached = e <= tol.value;
      if (reached || !ch.result || e < ch.error) {
        ch.value = j;
        ch.texture_size = res;
        ch.error = e;
        ch.result = h;
        ch.errors_after_term = std::move(errs);
      }
      if (reached) {
        ch.reached = true;
        ch.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        return ch;
      }
    }
  }
  ch.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return ch;
}

}  // namespace bf
