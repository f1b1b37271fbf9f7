// Catch2 main shared by the test tiers. A run in which a test case lacked its data
// (support/test_data.hpp) and nothing failed exits with kSkipExitCode, so that ctest, which
// runs one test case per process, reports that test case as skipped rather than passed.
// (No Catch2 listener: one would make every passing assertion allocate, which the
// allocation tests would see.)

#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "support/test_data.hpp"

int main(int argc, char* argv[]) {
  const int failures = Catch::Session().run(argc, argv);
  if (failures == 0 && tetseg::test::test_data_missing()) return tetseg::test::kSkipExitCode;
  return failures;
}
