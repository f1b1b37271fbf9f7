#include "support/test_data.hpp"

#include <catch2/catch.hpp>
#include <filesystem>

namespace tetseg::test {
namespace {
bool g_skipped = false;
}  // namespace

bool have_test_data(const std::string& path, const std::string& what) {
  std::error_code error;
  if (std::filesystem::exists(path, error)) return true;
#ifdef TETSEG_REQUIRE_TEST_DATA
  FAIL(what << " not found at " << path << " (required: TETSEG_REQUIRE_TEST_DATA=ON)");
#else
  WARN(what << " not found at " << path << ": test case skipped");
  g_skipped = true;
#endif
  return false;
}

bool current_test_case_skipped() {
  return g_skipped;
}
void reset_current_test_case_skipped() {
  g_skipped = false;
}

}  // namespace tetseg::test
