// Where the tests find the CLI, their data and the source tree. The paths are
// compiled into one object (test_paths.cpp), not into every test file, so the
// test sources compile the same wherever the tree is checked out.
// Force-included into every test source (tests/CMakeLists.txt).
#pragma once

namespace bf_test {
const char* cli_path();       // the brdf-factor executable of this build
const char* test_data_dir();  // tests/data
const char* source_dir();     // the repository root
}  // namespace bf_test

#define BF_CLI_PATH (::bf_test::cli_path())
#define BF_TEST_DATA_DIR (::bf_test::test_data_dir())
#define BRDF_FACTOR_SOURCE_DIR (::bf_test::source_dir())
