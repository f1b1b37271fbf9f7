// Catch2 main shared by the test tiers. A test case that lacks its data (support/test_data.hpp)
// is counted as skipped; a run whose test cases were all skipped exits with kSkipExitCode so
// that ctest, which runs one test case per process, reports it as skipped.

#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "support/test_data.hpp"

namespace {

int g_test_cases_run = 0;
int g_test_cases_skipped = 0;

struct SkipCounter : Catch::TestEventListenerBase {
  using TestEventListenerBase::TestEventListenerBase;
  void testCaseStarting(const Catch::TestCaseInfo& info) override {
    TestEventListenerBase::testCaseStarting(info);
    tetseg::test::reset_current_test_case_skipped();
    ++g_test_cases_run;
  }
  void testCaseEnded(const Catch::TestCaseStats& stats) override {
    if (tetseg::test::current_test_case_skipped()) ++g_test_cases_skipped;
    TestEventListenerBase::testCaseEnded(stats);
  }
};

}  // namespace

CATCH_REGISTER_LISTENER(SkipCounter)

int main(int argc, char* argv[]) {
  const int failures = Catch::Session().run(argc, argv);
  if (failures == 0 && g_test_cases_run > 0 && g_test_cases_skipped == g_test_cases_run) {
    return tetseg::test::kSkipExitCode;
  }
  return failures;
}
