// Catch2 main shared by the test tiers. A run in which a test case lacked its data
// (tetseg/testing/test_data.hpp) and nothing failed exits with kSkipExitCode, so that ctest, which
// runs one test case per process, reports that test case as skipped rather than passed.
// A test case that ran no assertion at all fails the run (every ctest entry asserts
// something): the default reporter is the console one that also records, when each test
// case ends, whether its totals hold an assertion. (Not a listener: Catch2 then reports every
// passing assertion, which allocates, and the allocation tests would see it.)

#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "tetseg/testing/test_data.hpp"

namespace {

std::vector<std::string> g_without_assertions;

struct AssertionCountingConsole : Catch::ConsoleReporter {
  using ConsoleReporter::ConsoleReporter;
  static std::string getDescription() {
    return "console, and fails test cases that ran no assertion";
  }
  void testCaseEnded(const Catch::TestCaseStats& stats) override {
    if (stats.totals.assertions.total() == 0) g_without_assertions.push_back(stats.testInfo.name);
    ConsoleReporter::testCaseEnded(stats);
  }
};

}  // namespace

CATCH_REGISTER_REPORTER("tetseg", AssertionCountingConsole)

int main(int argc, char* argv[]) {
  Catch::Session session;
  if (const int code = session.applyCommandLine(argc, argv)) return code;
  if (session.configData().reporterName == "console") session.configData().reporterName = "tetseg";
  const int failures = session.run();
  for (const std::string& name : g_without_assertions)
    std::fprintf(stderr, "test case without any assertion (it cannot fail): %s\n", name.c_str());
  if (!g_without_assertions.empty())
    return failures + static_cast<int>(g_without_assertions.size());
  if (failures == 0 && tetseg::test::test_data_missing()) return tetseg::test::kSkipExitCode;
  return failures;
}
