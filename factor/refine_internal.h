// Internal to refine() (factor/refine.h): its objectives as an enum and one
// sample's residual block, for refine.cpp and the GradientChecker test. Not
// part of the library's public interface.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace ceres {
class CostFunction;
}

namespace bf::detail {

// RefineOptions::objective: "linear", "cosine", "blend".
enum class RefineObjective { Linear, Cosine, Blend };

// The objective named s; throws std::invalid_argument naming the field
// (objective), the names expected and s.
RefineObjective parse_refine_objective(const std::string& s);

// The residual block of one sample and channel in refine(): `weights` are the
// merged stencil weights of the distinct texels (one 1-double parameter block
// each: the texel's log value in this channel), f the sample's value in the
// channel, sw = sqrt(w_k / 3W), cosw the cosine factor (1 unless Cosine), A
// the channel's constant, scale the unit of linear residuals (mean of A), eps
// and subtract_eps as in the factorization. Blend gives 2 residuals (log,
// linear), else 1.
std::unique_ptr<ceres::CostFunction> make_refine_sample_cost(const std::vector<double>& weights, double f,
                                                             double sw, double cosw, double A, double scale,
                                                             double eps, bool subtract_eps,
                                                             RefineObjective objective, double blend_weight);

}  // namespace bf::detail
