// Sample-list CSV (DESIGN.md §5), input and output:
//   header  theta_i,phi_i,theta_o,phi_o,r,g,b[,weight]
//   angles in radians (frame of brdf.h), values in 1/sr; '#' starts a comment line.
#pragma once

#include <string>

#include "brdfs/sampleset.h"

namespace bf {

// Reads a sample list. Rows with negative/NaN values or below-horizon angles are
// kept but masked (counted in the SampleSet). Throws std::invalid_argument naming
// path:line, what was expected and what was found, for a missing or wrong
// header, a wrong column count, a non-numeric cell, or angles out of range
// (theta outside [0, pi], phi outside [-2pi, 2pi]).
SampleSet read_sample_csv(const std::string& path);
// Writes every sample (masked ones too, so the file round-trips), atomically.
void write_sample_csv(const SampleSet& s, const std::string& path);

}  // namespace bf
