// libFuzzer target: the factorization .json sidecar loader
// (factor/export.h load_factorization; texture files it names will not exist).
#include <exception>

#include "factor/export.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = bf_fuzz::write_temp(data, size, ".json");
  try {
    bf::load_factorization(path);
  } catch (const std::exception&) {
  }
  return 0;
}
