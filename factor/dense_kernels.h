// Dense linear-algebra kernels of the inner-loop fit, compiled once per
// instruction set and chosen at start-up from the CPU that runs the process
// (runtime dispatch): the default (portable, x86-64 baseline) build then runs
// the Cholesky with AVX2+FMA or AVX-512 where the machine has them.
//
// Each instruction-set variant lives in its own translation unit
// (dense_kernels_<variant>.cpp, which includes dense_kernels_impl.inc) with its
// own copy of Eigen in a renamed namespace, and only plain pointers cross the
// boundary, so no Eigen template instance (or inline function with a different
// alignment) compiled with AVX flags can be merged by the linker into code that
// runs on a machine without AVX (docs/speed.md, "Kernel variants").
#pragma once

#include <string>
#include <vector>

namespace bf::kernels {

// Factors the n x n symmetric positive definite matrix A (column-major,
// leading dimension n, only the lower triangle read) in place into its lower
// Cholesky factor and overwrites B (n x nrhs, column-major, leading dimension
// n) with A^-1 B. Returns false (A and B then undefined) if A is not
// numerically positive definite.
bool llt_solve(double* A, long n, double* B, long nrhs);

// llt_solve for a matrix whose leading n1 x n1 block is banded (the fit's first
// joint term: bilinear cells and Laplacian couple texels at most 2 rows apart).
// That block is factored in its band, the n - n1 trailing unknowns through the
// Schur complement A22 - L21 L21^T, with the trailing unknowns ordered by their
// first coupled head column (a row of L21 is zero before it, and the fit's
// coupling block is sparse: the products skip that staircase; the solution
// comes back in the original order). The same factorization as llt_solve up
// to rounding; with n1 = n a banded Cholesky of the whole matrix; falls back to
// llt_solve when the head's bandwidth exceeds n1 / 4 or n1 is 0. Scratch
// memory is kept per thread.
bool llt_solve_banded_head(double* A, long n, long n1, double* B, long nrhs);

// The variant llt_solve uses: "generic", "avx2" (AVX2 + FMA) or "avx512"
// (AVX-512 F/DQ/VL + AVX2 + FMA). Chosen once, on first use: avx2 if the CPU
// (and the OS) support it, else generic, unless the environment variable
// BRDF_FACTOR_KERNEL names another supported variant (benchmarks, tests).
// Throws std::invalid_argument if BRDF_FACTOR_KERNEL names an unknown or
// unsupported variant.
std::string active_variant();

// The variants compiled into this build that this CPU can run, generic first.
std::vector<std::string> supported_variants();

// llt_solve with a given variant. Throws std::invalid_argument naming the
// variant if it is unknown or this CPU cannot run it.
bool llt_solve_with(const std::string& variant, double* A, long n, double* B, long nrhs);
bool llt_solve_banded_head_with(const std::string& variant, double* A, long n, long n1, double* B, long nrhs);

}  // namespace bf::kernels
