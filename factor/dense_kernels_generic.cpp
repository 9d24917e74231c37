// The baseline (x86-64 / the build's own flags) variant of the dense kernels.
#define BF_KERNEL_NS generic
#include "factor/dense_kernels_impl.inc"
