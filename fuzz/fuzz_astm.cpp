// libFuzzer target: the Cornell .astm reader (brdfs/measured.h read_astm)
// and, from the same bytes, the loader that turns its result into samples.
#include <exception>

#include "brdfs/catalogue.h"
#include "brdfs/measured.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = bf_fuzz::write_temp(data, size, ".astm");
  try {
    bf::read_astm(path);
    bf::Catalogue::builtin().make(path);
  } catch (const std::exception&) {
  }
  return 0;
}
