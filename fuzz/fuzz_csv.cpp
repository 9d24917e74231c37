// libFuzzer target: the sample-list CSV reader (brdfs/sample_csv.h).
#include <exception>

#include "brdfs/sample_csv.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = bf_fuzz::write_temp(data, size, ".csv");
  try {
    bf::read_sample_csv(path);
  } catch (const std::exception&) {
  }
  return 0;
}
