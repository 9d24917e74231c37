// Sample-list CSV (docs/design.md §5), input and output:
//   header  theta_i,phi_i,theta_o,phi_o,r,g,b[,weight]
//   angles in radians (frame of brdf.h), values in 1/sr; lines whose first
//   non-blank character is '#' are comments; blank lines are skipped; CRLF and
//   a UTF-8 byte-order mark are accepted.
#pragma once

#include <string>

#include "brdfs/sampleset.h"

namespace bf {

// Upper bound on the rows of one sample list.
constexpr size_t kMaxCsvSamples = 100'000'000;

// Reads a sample list. Rows with negative/NaN/Inf values or weights, or with
// below-horizon angles (theta in (pi/2, pi]), are kept but masked (counted in
// the SampleSet by reason). Throws std::invalid_argument naming path:line,
// what was expected and what was found, for each failure kind:
//   - the file cannot be opened; it is empty or has only comments (no header);
//   - the header has not 7 or 8 columns, or a column name differs from
//     theta_i,phi_i,theta_o,phi_o,r,g,b[,weight];
//   - a row has a different number of cells than the header;
//   - a cell is empty or not entirely a number;
//   - theta outside [0, pi] or phi outside [-2pi, 2pi] (or NaN/Inf angles);
//   - a header but no rows; more than kMaxCsvSamples rows; a line over 64 KiB.
SampleSet read_sample_csv(const std::string& path);

// Writes every sample (masked ones too, so the file round-trips), atomically
// (path + ".tmp", then rename). Angles use to_spherical (theta in [0, pi],
// phi in (-pi, pi]), 17 significant digits. No NaN/Inf is ever written:
// a non-finite value or weight is written as -1 and a non-finite direction as
// theta = pi, which read back as masked for the same reason. The description becomes one '#'
// comment line. Throws std::runtime_error naming the path when it cannot be written.
void write_sample_csv(const SampleSet& s, const std::string& path);

}  // namespace bf
