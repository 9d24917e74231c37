// The homomorphic fit's assembly kernels (factor/fit_assembly.cpp and fit_assembly_sparse.cpp, dense
// path): per-sample lookups, per-cell self-product sums and the cross products
// of two lookups scattered into the normal matrix. Like the Cholesky
// (factor/dense_kernels.h) they are compiled once per instruction set and
// chosen at start-up; unlike it they are compiled with -ffp-contract=off, so
// every variant performs the same multiplications and additions in the same
// order as the portable code and the normal matrix is bit for bit the same on
// every machine (the search's golden-section decisions, and so its errors,
// do not depend on the CPU).
//
// Bilinear weights of a lookup with fractions (a, b) in its cell, corners in
// the order (i, j), (i+1, j), (i, j+1), (i+1, j+1):
//   b = ((1-a)(1-b), a(1-b), (1-a)b, ab).
// Only plain pointers cross the boundary.
#pragma once

#include <cstddef>
#include <cstdint>

namespace bf::kernels {

// Doubles per cell in cell_sums' output: Q (4 x 4, column j holds
// sum_k (w_k b_k) b_kj, entry (i, j) = sum w b_i b_j; only i >= j is used),
// then R (3 channels x 4 corners: sum_k w_k b_ki r_kc at 16 + 4 c + i).
constexpr int kCellDoubles = 28;

// Per point k (x: n x 4, row-major): u = m[0..3].x + off and v = m[4..7].x + off
// (summed left to right, then off), each clamped to [0, res - 1]; the cell's
// lower-left texel i = min(int(u), res - 2), j likewise; cell[k] = j * res + i,
// fa[k] = u - i, fb[k] = v - j; touched[cell[k]] = 1 (touched: res * res
// bytes, not cleared here).
void lookup_cells(std::size_t n, const double* x, const double m[8], double off, int res, int* cell,
                  double* fa, double* fb, std::uint8_t* touched);

// Adds, in sample order, every sample's self products into its cell:
// acc[kCellDoubles * cell[k] + ...] (layout above) with weights w and the three
// channels' targets r0, r1, r2.
void cell_sums(std::size_t n, const int* cell, const double* fa, const double* fb, const double* w,
               const double* r0, const double* r1, const double* r2, double* acc);

// Cross products of lookup p and lookup q, in sample order:
//   A[ip[a] * lda + iq[c]] += (w_k bp_a) bq_c   for a, c in 0..3,
// with ip = corners_p + 4 cell_p[k], iq = corners_q + 4 cell_q[k] (each a
// cell's 4 unknowns in corner order, iq[1] = iq[0] + 1 and iq[3] = iq[2] + 1).
void cross_products(std::size_t n, const int* cell_p, const double* fa_p, const double* fb_p,
                    const int* cell_q, const double* fa_q, const double* fb_q, const double* w,
                    const int* corners_p, const int* corners_q, double* A, std::size_t lda);

}  // namespace bf::kernels
