// The SVD baseline (Kautz & McCool 1999): the BRDF tabulated as a matrix over
// a parabolic texel grid of (wi, wo) or (h, d), truncated to rank K by SVD per
// RGB channel (optionally in McCool's log space), evaluated anywhere by
// bilinear lookups of the factor textures. Also the pieces the SH baselines
// share: the parabolic texel grid and tolerance-driven selection of a size
// knob (rank, order) with its time and error (docs/design.md §6, §9).
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "brdfs/directions.h"
#include "brdfs/sampleset.h"
#include "factor/factorization.h"
#include "factor/projection.h"
#include "factor/size_choice.h"
#include "solvers/svd.h"

namespace bf {

// The res x res parabolic texel grid used by the SVD and SH-K baselines.
// Texel (i, j), index j*res + i, sits at the parabolic point
//   p = (-1 + 2 i/(res-1), -1 + 2 j/(res-1)),
// so the grid's outer texels lie on the disk edge; the texel coordinates of a
// point p are s = (p + 1)/2 * (res - 1), read with bilinear() of
// factor/projection.h. Only "masked" texels are stored and computed: the
// corners of every grid cell that meets the closed unit disk (what bilinear
// lookups of points in the disk can read). A texel is evaluated at the
// direction of its point pulled in to radius 1 - rim_inset when it lies
// further out: texels on or outside the disk edge take the BRDF's value at
// the direction of the same azimuth at radius 1 - rim_inset (SVD default:
// half a grid spacing in, see SvdOptions::rim_inset), a continuous
// extension; a direction exactly on the horizon would read 0 from every BRDF.
struct DiskGrid {
  int res = 0;
  std::vector<int> texels;  // masked texel indices, ascending
  std::vector<int> slot;    // res*res entries: position in texels, or -1
  // Throws std::invalid_argument unless 2 <= res <= 1024.
  static DiskGrid make(int res);
  Vec2 point(int texel) const;
  // Unit direction (z > 0) at which texel `texel` is evaluated (see above).
  Vec3 direction(int texel, double rim_inset) const;
  // Texture coordinates of a parabolic point.
  Eigen::Vector2d coords(const Vec2& p) const;
  size_t count() const { return texels.size(); }
};

struct SvdOptions {
  // Rows = first half of the 4D point, columns = second half: (p(wi), p(wo))
  // for wiwo, (p(h), p(d)) for halfdiff (docs/design.md §2).
  Parameterization param = Parameterization::WiWo;
  int res = 32;             // texture_size: res x res grid for rows and for columns, 2..256
  int rank = 1;             // terms K >= 1 (capped at the number of masked texels)
  bool log = false;         // decompose g = log((f + eps A)/A) instead of f
  double eps = 1e-5;        // log-space bias (docs/design.md §2), 0 < eps <= 1
  bool subtract_eps = false;  // log reconstruction A exp(.) - eps A (else A exp(.)); Cole omits it
  // DiskGrid: texels beyond radius 1 - rim_inset are evaluated at that radius.
  // 0 (default) = half the grid spacing, 1/(res-1): the rim texel takes the
  // BRDF's value in the middle of the outermost ring of cells, the region its
  // bilinear footprint covers inside the disk. A tiny inset (such as 1e-4,
  // theta 89.99 deg) tabulates the BRDF at grazing angles no sample set
  // reaches, where models with 1/(cos_i cos_o) (Cook-Torrance) are ~1e7: the
  // linear SVD then spends its terms on those texels and bilinear lookups
  // spread them over the outer cells (cole-cook-torrance, 16x16, rank 4:
  // lin_max ~5e4 for a BRDF peaking ~140 on the samples). [0, 0.5]
  double rim_inset = 0.0;
  // The inset in use: rim_inset, or 1/(res-1) (at most 0.5) when it is 0.
  double effective_rim_inset() const;
  // halfdiff only: texel pairs (h, d) whose wi or wo falls below the horizon
  // are no BRDF configuration; bilinear lookups near the horizon still read
  // them. true: fill them with the BRDF at wi, wo lifted to the rim elevation
  // (azimuth kept), a continuous extension; false: fill with 0, whose jump
  // (a jump to log(eps) in log mode) the low-rank SVD then has to fit.
  bool extend_below_horizon = true;
  bool float_textures = false;  // round factor textures to float (what an EXR export holds)
  // Throws std::invalid_argument naming the field, its value and the rule.
  void validate() const;
};

// The tabulated matrix the SVD decomposes, per RGB channel (rows x cols over
// grid.texels), already log-transformed when log is set. Entry (r, c) is the
// BRDF's own eval at the texel directions: a measured BRDF is resampled by its
// own interpolation; halfdiff pairs below the horizon hold the lifted
// extension or 0 (SvdOptions::extend_below_horizon).
struct SvdTable {
  Parameterization param = Parameterization::WiWo;
  DiskGrid grid;                      // rows and columns share it
  std::array<Eigen::MatrixXd, 3> M;   // per channel, grid.count() x grid.count()
  bool log = false;
  double eps = 1e-5;
  // Log mode: per-channel mean of f over the in-domain entries (both texel
  // points inside the closed disk, wi and wo above the horizon); else 1.
  Rgb A = Rgb::Ones();
  double seconds = 0;                 // wall time of the tabulation
};
SvdTable tabulate_svd(const Brdf& brdf, const SvdOptions& opt);

// f_c(wi, wo) = sum_k sigma_ck u_ck(s_row) v_ck(s_col)             (linear)
// f_c(wi, wo) = A_c exp(sum_k sigma_ck u_ck(s_row) v_ck(s_col)) [- eps A_c]   (log)
// with s_row, s_col the texture coordinates of the two halves of
// to_point(param, wi, wo) and u, v read by bilinear interpolation; the result
// is clamped at 0 (as a renderer would) and is 0 below the horizon.
class SvdFactorization final : public Factorization {
 public:
  // svd[c]: decomposition of channel c of the table built with opt on grid;
  // A: the table's A (log mode). seconds: wall time of tabulation + SVD.
  SvdFactorization(const SvdOptions& opt, DiskGrid grid, Rgb A, std::array<TruncatedSvd, 3> svd,
                   double seconds);

  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  // The model before the clamp at 0 (and before exp in log mode): the value
  // the rank-K matrix holds at grid nodes.
  Rgb eval_raw(const Vec3& wi, const Vec3& wo) const;
  std::string name() const override { return "svd"; }
  std::string to_string() const override;
  bool isotropic() const override { return false; }
  bool reciprocal() const override { return false; }
  std::string method() const override { return "svd"; }
  // K * (rows + cols) * 3 masked texels + 3K singular values (+ 3 A + 1 eps in log mode).
  size_t storage_floats() const override;
  nlohmann::json describe() const override;
  // Outputs (factor/factorization.h), defined in factor/baseline_export.cpp.
  ExportedFiles write_export_files(const std::string& dir, const std::string& stem,
                                   const std::string& origin) const override;
  std::string glsl(const std::string& stem, const std::string& origin) const override;
  std::optional<ShaderView> viewer_data() const override;

  int rank() const { return rank_; }
  const SvdOptions& options() const { return opt_; }
  const DiskGrid& grid() const { return grid_; }
  const Rgb& A() const { return A_; }
  // Factor vectors over grid().texels (unit norm), and sigma_ck.
  const Eigen::MatrixXd& U(int c) const { return svd_[c].U; }
  const Eigen::MatrixXd& V(int c) const { return svd_[c].V; }
  double sigma(int c, int k) const { return svd_[c].sigma[k]; }
  // All singular values of channel c (including the discarded ones).
  const Eigen::VectorXd& singular_values(int c) const { return svd_[c].sigma; }
  // Eckart-Young error of channel c: sqrt of the discarded sigma^2 (matrix space).
  double discarded_norm(int c) const;
  // Full res*res texture of term k, channel c (0 outside the mask): the row
  // factor u_ck or the column factor v_ck.
  std::vector<double> row_texture(int c, int k) const;
  std::vector<double> col_texture(int c, int k) const;
  // Negative texels over all stored u and v textures and channels: what an
  // unsigned texture format cannot hold (a log-mode factor is combined through
  // exp, so there negative texels are expected and harmless).
  size_t negative_texels() const { return negative_texels_; }
  // The rank-k prefix (k <= rank()): same decomposition, fewer terms.
  std::shared_ptr<SvdFactorization> truncated(int k) const;
  double seconds() const { return seconds_; }

 private:
  double term_sum(int c, const Bilinear& row, const Bilinear& col) const;
  SvdOptions opt_;
  DiskGrid grid_;
  std::array<TruncatedSvd, 3> svd_;
  int rank_;
  Rgb A_;
  size_t negative_texels_ = 0;
  double seconds_ = 0;
};

// Tabulate, decompose, wrap. Throws std::invalid_argument from opt.validate(),
// or when log mode meets a BRDF whose mean is 0 in a channel.
std::shared_ptr<SvdFactorization> fit_svd(const Brdf& brdf, const SvdOptions& opt);
// Decompose an existing table (rank and float_textures from opt).
std::shared_ptr<SvdFactorization> fit_svd(const SvdTable& table, const SvdOptions& opt);

// ---------------------------------------------------------------------------
// Tolerance-driven size selection of the SVD (types in factor/size_choice.h).

// Smallest rank K <= max_rank whose SVD approximation scores <= tol on
// `samples` (metrics of factor/metrics.h, log transform from the samples).
// One tabulation and one SVD at max_rank; every K is a prefix of it.
// base.rank is ignored.
SizeChoice select_svd_rank(const Brdf& brdf, const SampleSet& samples, const SvdOptions& base,
                           const Tolerance& tol, int max_rank);

// Resolution and rank from one tolerance: the smallest resolution of `ladder`
// (ascending) at which some rank <= max_rank reaches tol, with the smallest
// such rank there (select_svd_rank per resolution, stopping at the first
// resolution that reaches). Nothing reaches: the lowest error tried,
// reached = false. tried lists every (resolution, rank) scored; seconds is
// the wall time of the whole selection. base.res and base.rank are ignored.
SizeChoice select_svd_size(const Brdf& brdf, const SampleSet& samples, const SvdOptions& base,
                           const Tolerance& tol, int max_rank, const std::vector<int>& ladder);

}  // namespace bf
