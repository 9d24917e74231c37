// The AVX2 + FMA variant of the dense kernels, compiled with -mavx2 -mfma
// (factor/CMakeLists.txt); called only on CPUs that have both.
#define BF_KERNEL_NS avx2
#define BF_KERNEL_EIGEN_NS EigenBfAvx2
#include "factor/dense_kernels_impl.inc"
