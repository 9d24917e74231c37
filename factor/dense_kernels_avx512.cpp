// The AVX-512 variant of the dense kernels, compiled with -mavx512f
// -mavx512dq -mavx512vl -mavx2 -mfma (factor/CMakeLists.txt); called only on
// CPUs that have all of them.
#define BF_KERNEL_NS avx512
#define BF_KERNEL_EIGEN_NS EigenBfAvx512
#include "factor/dense_kernels_impl.inc"
