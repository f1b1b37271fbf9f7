#include "tetseg/testing/test_data.hpp"

#include <catch2/catch.hpp>
#include <filesystem>

namespace tetseg::test {
namespace {
bool g_missing = false;
}  // namespace

bool have_test_data(const std::string& path, const std::string& what) {
  std::error_code error;
  if (std::filesystem::exists(path, error)) return true;
#ifdef TETSEG_REQUIRE_TEST_DATA
  FAIL(what << " not found at " << path << " (required: TETSEG_REQUIRE_TEST_DATA=ON)");
#else
  WARN(what << " not found at " << path << ": test case skipped");
  SUCCEED("skipped: the run exits with kSkipExitCode");  // not a test without assertions
  g_missing = true;
#endif
  return false;
}

bool test_data_missing() {
  return g_missing;
}

}  // namespace tetseg::test
