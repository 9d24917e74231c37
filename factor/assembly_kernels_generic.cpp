// The portable variant of the assembly kernels (the build's own flags, plus
// -ffp-contract=off: factor/CMakeLists.txt).
#define BF_KERNEL_NS generic
#include "factor/assembly_kernels_impl.inc"
