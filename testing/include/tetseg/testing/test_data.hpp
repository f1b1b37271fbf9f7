#pragma once
// Tests that need data outside the repository (../shared, the CGAL demo meshes) ask for it here.
// When the data is missing, the test fails if the build requires test data
// (TETSEG_REQUIRE_TEST_DATA, ON in scripts/test.sh); otherwise it returns early with a
// warning, and the test executable exits with kSkipExitCode when nothing failed, which ctest
// (one test case per process) reports as "Skipped" (SKIP_RETURN_CODE), never as passed.

#include <string>

namespace tetseg::test {

/// Exit code of a test run whose test cases were all skipped (ctest's SKIP_RETURN_CODE).
constexpr int kSkipExitCode = 77;

/// True when `path` (a file or folder) exists. Otherwise fails the current test case if test
/// data is required, or records the skip with a warning naming `what` and `path`; the caller
/// then returns from the test case.
bool have_test_data(const std::string& path, const std::string& what);

/// Whether have_test_data found data missing in this run (tests/main.cpp).
bool test_data_missing();

}  // namespace tetseg::test
