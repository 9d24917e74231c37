// Runtime dispatch of the assembly kernels (see assembly_kernels.h): the AVX2
// variant wherever the Cholesky runs an AVX variant (factor/dense_kernels.h,
// BRDF_FACTOR_KERNEL), else the portable one. Both compute the same sums.
#include "factor/assembly_kernels.h"
#include "factor/dense_kernels.h"

namespace bf::kernels {

#define BF_ASSEMBLY_DECLS                                                                             \
  void lookup_cells(std::size_t, const double*, const double[8], double, int, int*, double*, double*,  \
                    std::uint8_t*);                                                                    \
  void cell_sums(std::size_t, const int*, const double*, const double*, const double*, const double*, \
                 const double*, const double*, double*);                                               \
  void cross_products(std::size_t, const int*, const double*, const double*, const int*,              \
                      const double*, const double*, const double*, const int*, const int*, double*,   \
                      std::size_t);
namespace generic {
BF_ASSEMBLY_DECLS
}
#ifdef BF_FACTOR_X86_KERNELS
namespace avx2 {
BF_ASSEMBLY_DECLS
}
#endif
#undef BF_ASSEMBLY_DECLS

namespace {

struct Table {
  decltype(&generic::lookup_cells) lookup;
  decltype(&generic::cell_sums) sums;
  decltype(&generic::cross_products) cross;
};

const Table& table() {
  static const Table t = [] {
#ifdef BF_FACTOR_X86_KERNELS
    const std::string v = active_variant();
    if (v == "avx2" || v == "avx512") return Table{&avx2::lookup_cells, &avx2::cell_sums, &avx2::cross_products};
#endif
    return Table{&generic::lookup_cells, &generic::cell_sums, &generic::cross_products};
  }();
  return t;
}

}  // namespace

void lookup_cells(std::size_t n, const double* x, const double m[8], double off, int res, int* cell,
                  double* fa, double* fb, std::uint8_t* touched) {
  table().lookup(n, x, m, off, res, cell, fa, fb, touched);
}

void cell_sums(std::size_t n, const int* cell, const double* fa, const double* fb, const double* w,
               const double* r0, const double* r1, const double* r2, double* acc) {
  table().sums(n, cell, fa, fb, w, r0, r1, r2, acc);
}

void cross_products(std::size_t n, const int* cell_p, const double* fa_p, const double* fb_p,
                    const int* cell_q, const double* fa_q, const double* fb_q, const double* w,
                    const int* corners_p, const int* corners_q, double* A, std::size_t lda) {
  table().cross(n, cell_p, fa_p, fb_p, cell_q, fa_q, fb_q, w, corners_p, corners_q, A, lda);
}

}  // namespace bf::kernels
