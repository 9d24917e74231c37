// MERL isotropic BRDF tables (.binary): reader, writer, the MERL half/difference
// angles, and MerlBrdf, which evaluates a table.
//
// File layout (MERL's reference BRDFRead.cpp): three little-endian int32 dims
// (90, 90, 180), then 3 * 1,458,000 little-endian float64: all red, then all
// green, then all blue; file size 12 + 34,992,000 = 34,992,012 bytes. Cell
// index = phi_d_idx + 180 * (theta_d_idx + 90 * theta_h_idx). A stored value
// times kMerlScale[c] is the BRDF in 1/sr; negative values mark missing cells.
//
// Angles: Rusinkiewicz's half/difference angles computed as MERL does, with
// n = (0,0,1) and b = (0,1,0): h = normalize(wi + wo), theta_h = angle(h, n),
// phi_h = atan2(h.y, h.x); d = rotate(rotate(wi, n, -phi_h), b, -theta_h);
// theta_d = angle(d, n), phi_d = atan2(d.y, d.x). (This is not the frame of
// directions.h's half_diff, which builds (r, s, h) from the tangent.) wi (the
// light direction) plays MERL's "in". phi_h is dropped (isotropy), and phi_d is
// folded into [0, pi) by f(phi_d) = f(phi_d + pi) (reciprocity).
//
// Bins: theta_h_idx = floor(90 * sqrt(theta_h / (pi/2))) (non-linear: fine near
// the specular peak), theta_d_idx = floor(90 * theta_d / (pi/2)),
// phi_d_idx = floor(180 * phi_d / pi), each clamped to its range. Bin centres
// are the midpoints in index space: theta_h = ((i + 0.5) / 90)^2 * pi/2,
// theta_d = (j + 0.5) / 90 * pi/2, phi_d = (k + 0.5) / 180 * pi.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "brdfs/brdf.h"
#include "brdfs/sampleset.h"

namespace bf {

constexpr int kMerlThetaH = 90;
constexpr int kMerlThetaD = 90;
constexpr int kMerlPhiD = 180;
constexpr size_t kMerlCells = size_t{kMerlThetaH} * kMerlThetaD * kMerlPhiD;  // 1,458,000
constexpr uint64_t kMerlFileBytes = 12 + 3 * uint64_t{kMerlCells} * 8;        // 34,992,012
constexpr double kMerlScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

struct MerlAngles {
  double theta_h = 0;  // [0, pi/2] for upper-hemisphere pairs
  double theta_d = 0;  // [0, pi/2] for upper-hemisphere pairs
  double phi_d = 0;    // (-pi, pi], not folded
};
// wi, wo: unit vectors. wi = -wo (h undefined) gives h = n; phi_h is taken
// as 0 when h is within 1e-12 of n (so mirror pairs give phi_d = phi_i).
MerlAngles merl_half_diff(const Vec3& wi, const Vec3& wo);
// Inverse with phi_h = 0: the pair (wi, wo) with these MERL angles.
void merl_half_diff_inverse(const MerlAngles& a, Vec3& wi, Vec3& wo);

// Bin indices (reference truncation, clamped) and bin centres (radians).
int merl_theta_h_index(double theta_h);
int merl_theta_d_index(double theta_d);
int merl_phi_d_index(double phi_d);  // folds phi_d into [0, pi) first
double merl_theta_h_centre(int i);
double merl_theta_d_centre(int j);
double merl_phi_d_centre(int k);
inline size_t merl_cell(int h, int d, int p) {
  return (static_cast<size_t>(h) * kMerlThetaD + d) * kMerlPhiD + p;
}

// A MERL table in memory.
struct MerlTable {
  // raw[c * kMerlCells + merl_cell(h, d, p)]: channel c (0 = R, 1 = G, 2 = B)
  // exactly as stored in the file (BRDF / kMerlScale[c]); finite; negative in
  // any channel = the cell is missing. Size 3 * kMerlCells.
  std::vector<double> raw;

  bool missing(size_t cell) const {
    return raw[cell] < 0.0 || raw[kMerlCells + cell] < 0.0 || raw[2 * kMerlCells + cell] < 0.0;
  }
  // BRDF of a cell in 1/sr (meaningless when missing()).
  Rgb value(size_t cell) const {
    return Rgb(raw[cell] * kMerlScale[0], raw[kMerlCells + cell] * kMerlScale[1],
               raw[2 * kMerlCells + cell] * kMerlScale[2]);
  }
  size_t missing_count() const;
};

// Reads a MERL .binary file. Before allocating anything it checks, one rule per
// message ("merl: ..." with the path): the file size is at least the 12-byte
// header, dims[0] == 90, dims[1] == 90, dims[2] == 180 (so negative, huge and
// swapped dims are rejected; the product is computed in 64 bits), and the
// file size is exactly 34,992,012 bytes. Then it reads the payload and rejects
// NaN/Inf (naming channel and bin). Throws std::invalid_argument (bad
// content) or std::runtime_error (I/O).
MerlTable read_merl(const std::string& path);

// Writes a table in the layout above, atomically (path + ".tmp", then
// rename); nothing is left at `path` on failure. Throws std::invalid_argument
// if the table has the wrong size or a NaN/Inf entry, std::runtime_error on
// I/O failure.
void write_merl(const MerlTable& table, const std::string& path);

struct MerlTabulateStats {
  size_t cells = 0;          // kMerlCells
  size_t below_horizon = 0;  // bin centre has wi.z <= 0 or wo.z <= 0: written as missing
  size_t invalid = 0;        // brdf returned NaN, Inf or a negative value: written as missing
};
// Tabulates a BRDF at the bin centres (phi_h = 0, phi_d in [0, pi): the MERL
// format assumes an isotropic, reciprocal BRDF). Missing cells hold -1.
MerlTable merl_tabulate(const Brdf& brdf, MerlTabulateStats* stats = nullptr);

enum class MerlLookup {
  Nearest,  // the reference reader: the bin containing the angles
  Linear,   // trilinear in (theta_h index, theta_d index, phi_d index) space
};
// "nearest" | "linear"; throws std::invalid_argument naming the accepted values.
MerlLookup parse_merl_lookup(const std::string& s, const std::string& what);

// The measure d(wi) d(wo) of the pairs whose (theta_h, theta_d, phi_d) lie in
// the cells [h, h + nh) x [d, d + nd) x [p, p + np), up to a constant factor,
// at the first cell's centre: with dwi dwo = 4 cos(theta_d) dw_h dw_d,
// sin(theta_h) dtheta_h sin(theta_d) cos(theta_d) dtheta_d dphi_d, where the
// theta_h bins are uniform in sqrt(theta_h).
double merl_cell_measure(int h, int d, int nh = 1, int nd = 1, int np = 1);

// A BRDF given by a MERL table (shared, so copies are cheap).
//
// eval: 0 below the horizon. Nearest: the cell's value, 0 if the cell is
// missing. Linear: trilinear interpolation between the 8 surrounding bin
// centres (theta_h and theta_d clamped at the ends, phi_d periodic with
// period pi); missing corners are dropped and the remaining weights
// renormalized; 0 if all 8 are missing. Never negative, never NaN.
class MerlBrdf final : public Brdf {
 public:
  // source: where the table came from (a path), for to_string().
  MerlBrdf(std::shared_ptr<const MerlTable> table, MerlLookup lookup, std::string source);

  Rgb eval(const Vec3& wi, const Vec3& wo) const override;
  std::string name() const override { return "merl"; }
  std::string to_string() const override;
  // False where eval has no table value to return (the nearest cell missing;
  // linear: all 8 corners missing) and eval returns 0 as a fill.
  bool defined_at(const Vec3& wi, const Vec3& wo) const override;

  // One sample per stride-th cell in each of the three dimensions, at bin
  // centres (phi_h = 0); missing cells get value -1 and are masked (invalid),
  // so no fit ever uses them. stride 1 gives all 1,458,000 cells. Throws
  // std::invalid_argument for stride outside 1..90. measure_weights: each
  // sample weighted by the measure of the cells it stands for in the
  // hemisphere-pair space (merl_cell_measure), normalized to mean 1 over the
  // valid samples; else unweighted.
  SampleSet samples(int stride = 1, bool measure_weights = false) const;
  const MerlTable& table() const { return *table_; }
  MerlLookup lookup() const { return lookup_; }
  const std::string& source() const { return source_; }

 private:
  // eval's value, or nullopt where the table has none (above the horizon).
  std::optional<Rgb> lookup_value(const Vec3& wi, const Vec3& wo) const;
  std::shared_ptr<const MerlTable> table_;
  MerlLookup lookup_;
  std::string source_;
};

}  // namespace bf
