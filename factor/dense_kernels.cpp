// Runtime dispatch of the dense kernels (see dense_kernels.h).
#include "factor/dense_kernels.h"

#include <cstdlib>
#include <stdexcept>

namespace bf::kernels {

namespace generic {
bool llt_solve(double* A, long n, double* B, long nrhs);
bool llt_solve_banded_head(double* A, long n, long n1, double* B, long nrhs);
}
#ifdef BF_FACTOR_X86_KERNELS
namespace avx2 {
bool llt_solve(double* A, long n, double* B, long nrhs);
bool llt_solve_banded_head(double* A, long n, long n1, double* B, long nrhs);
}
namespace avx512 {
bool llt_solve(double* A, long n, double* B, long nrhs);
bool llt_solve_banded_head(double* A, long n, long n1, double* B, long nrhs);
}
#endif

namespace {

using LltFn = bool (*)(double*, long, double*, long);
using BandedFn = bool (*)(double*, long, long, double*, long);

struct Variant {
  const char* name;
  LltFn llt;
  BandedFn banded;
  bool (*supported)();
};

bool always() { return true; }
#ifdef BF_FACTOR_X86_KERNELS
// __builtin_cpu_supports also checks that the OS saves the AVX/AVX-512 state.
bool has_avx2() { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }
bool has_avx512() {
  return has_avx2() && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512vl");
}
#endif

const Variant kVariants[] = {
    {"generic", &generic::llt_solve, &generic::llt_solve_banded_head, &always},
#ifdef BF_FACTOR_X86_KERNELS
    {"avx2", &avx2::llt_solve, &avx2::llt_solve_banded_head, &has_avx2},
    {"avx512", &avx512::llt_solve, &avx512::llt_solve_banded_head, &has_avx512},
#endif
};

const Variant& find(const std::string& name) {
  std::string known;
  for (const Variant& v : kVariants) {
    if (name == v.name) {
      if (!v.supported())
        throw std::invalid_argument("kernel variant \"" + name + "\": this CPU does not support it");
      return v;
    }
    known += known.empty() ? v.name : std::string(", ") + v.name;
  }
  throw std::invalid_argument("kernel variant: expected one of " + known + ", found \"" + name + "\"");
}

// The chosen variant: BRDF_FACTOR_KERNEL if set, else avx2 where supported,
// else generic. avx512 is not the default: Eigen's AVX-512 Cholesky is no
// faster than its AVX2 one at the sizes a fit solves, and slower at the
// largest dense ones (docs/speed.md, "Kernel variants"). Decided once per
// process.
const Variant& chosen() {
  static const Variant& v = [&]() -> const Variant& {
    if (const char* env = std::getenv("BRDF_FACTOR_KERNEL"); env && *env) {
      try {
        return find(env);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("BRDF_FACTOR_KERNEL: ") + e.what());
      }
    }
    for (const Variant& c : kVariants)
      if (std::string(c.name) == "avx2" && c.supported()) return c;
    return kVariants[0];
  }();
  return v;
}

}  // namespace

bool llt_solve(double* A, long n, double* B, long nrhs) { return chosen().llt(A, n, B, nrhs); }

bool llt_solve_banded_head(double* A, long n, long n1, double* B, long nrhs) {
  return chosen().banded(A, n, n1, B, nrhs);
}

std::string active_variant() { return chosen().name; }

std::vector<std::string> supported_variants() {
  std::vector<std::string> out;
  for (const Variant& v : kVariants)
    if (v.supported()) out.push_back(v.name);
  return out;
}

bool llt_solve_with(const std::string& variant, double* A, long n, double* B, long nrhs) {
  return find(variant).llt(A, n, B, nrhs);
}

bool llt_solve_banded_head_with(const std::string& variant, double* A, long n, long n1, double* B, long nrhs) {
  return find(variant).banded(A, n, n1, B, nrhs);
}

}  // namespace bf::kernels
