#pragma once
// Tests that need data outside the repository (../shared, the CGAL demo meshes) ask for it here.
// When the data is missing, the test fails if the build requires test data
// (TETSEG_REQUIRE_TEST_DATA, ON in scripts/test.sh); otherwise the test case is marked
// skipped, and the test executable exits with kSkipExitCode when every test case it ran was
// skipped, which ctest reports as "Skipped" (SKIP_RETURN_CODE), never as passed.

#include <string>

namespace tetseg::test {

/// Exit code of a test run whose test cases were all skipped (ctest's SKIP_RETURN_CODE).
constexpr int kSkipExitCode = 77;

/// True when `path` (a file or folder) exists. Otherwise fails the current test case if test
/// data is required, or marks it skipped with a warning naming `what` and `path`; the caller
/// then returns from the test case.
bool have_test_data(const std::string& path, const std::string& what);

/// Whether have_test_data marked the current test case skipped (used by tests/main.cpp).
bool current_test_case_skipped();
void reset_current_test_case_skipped();

}  // namespace tetseg::test
