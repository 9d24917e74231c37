// libFuzzer target: the pbrt-v2 .brdf reader (brdfs/measured.h read_pbrt_brdf)
// and the catalogue loader on the same bytes.
#include <exception>

#include "brdfs/catalogue.h"
#include "brdfs/measured.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = bf_fuzz::write_temp(data, size, ".brdf");
  try {
    bf::read_pbrt_brdf(path);
    bf::Catalogue::builtin().make(path);
  } catch (const std::exception&) {
  }
  return 0;
}
