#include "test_paths.h"

namespace bf_test {
const char* cli_path() { return BF_CLI_PATH_VALUE; }
const char* test_data_dir() { return BF_TEST_DATA_DIR_VALUE; }
const char* source_dir() { return BF_SOURCE_DIR_VALUE; }
}  // namespace bf_test
