// The AVX2 variant of the assembly kernels, compiled with -mavx2 and
// -ffp-contract=off (factor/CMakeLists.txt): wider registers, the same
// operations. Called only on CPUs that have AVX2.
#define BF_KERNEL_NS avx2
#include "factor/assembly_kernels_impl.inc"
