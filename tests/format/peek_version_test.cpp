#include <catch2/catch.hpp>

#include "format/support/test_assets.hpp"

using namespace tetseg;
using namespace tetseg::test;

TEST_CASE("peek_version reads the version that the envelope declares", "[format]") {
  const auto golden = read_file(std::string(TETSEG_SOURCE_DIR) + "/tests/golden/asset-v1.0.tetseg");
  REQUIRE(golden.size() > kHeaderBytes);
  std::uint16_t major = 99;
  std::uint16_t minor = 99;
  REQUIRE(format::peek_version(golden.data(), golden.size(), major, minor));
  REQUIRE(major == 1);
  REQUIRE(minor == 0);

  SECTION("A declared minor version is reported as written, even when unsupported.") {
    auto bytes = golden;
    put_le(bytes, kMinorAt, 7, 2);
    REQUIRE(format::peek_version(bytes.data(), bytes.size(), major, minor));
    REQUIRE(minor == 7);
  }
  SECTION("Bytes shorter than the envelope have no version.") {
    REQUIRE_FALSE(format::peek_version(golden.data(), kHeaderBytes - 1, major, minor));
    REQUIRE_FALSE(format::peek_version(nullptr, 0, major, minor));
  }
  SECTION("Bytes without the magic have no version.") {
    auto bytes = golden;
    bytes[1] ^= 0x20;
    REQUIRE_FALSE(format::peek_version(bytes.data(), bytes.size(), major, minor));
  }
}
