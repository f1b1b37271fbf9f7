// Loading assets through the runtime API (tetseg::load_asset), which wraps tetseg::format.
#include <catch2/catch.hpp>

#include "format/support/test_assets.hpp"
#include "tetseg/runtime/asset.hpp"

using tetseg::test::get_le;
using tetseg::test::golden_path;
using tetseg::test::read_file;

TEST_CASE("The runtime loads the golden asset and exposes its counts", "[format][runtime]") {
  tetseg::Asset asset;
  std::string why;
  REQUIRE(tetseg::load_asset_file(golden_path(), asset, &why) == tetseg::Status::kOk);
  INFO(why);
  const tetseg::format::Asset expected = tetseg::test::make_octahedron_asset();
  CHECK(asset.node_count() == 8);
  CHECK(asset.triangle_count() == 8);
  CHECK(asset.cluster_count() == 2);
  CHECK_FALSE(asset.empty());
  CHECK(tetseg::test::assets_equal(asset.data(), expected));

  SECTION("Loading the same bytes from memory gives the same asset.") {
    const auto bytes = read_file(golden_path());
    tetseg::Asset from_memory;
    REQUIRE(tetseg::load_asset(bytes.data(), bytes.size(), from_memory) == tetseg::Status::kOk);
    CHECK(tetseg::test::assets_equal(from_memory.data(), asset.data()));
  }
}

TEST_CASE("A failed runtime load leaves the asset empty and says why", "[format][runtime]") {
  auto bytes = read_file(golden_path());
  REQUIRE(bytes.size() > tetseg::test::kHeaderBytes);
  tetseg::Asset asset;
  REQUIRE(tetseg::load_asset(bytes.data(), bytes.size(), asset) == tetseg::Status::kOk);
  REQUIRE_FALSE(asset.empty());

  SECTION("A corrupted payload byte is a payload checksum failure.") {
    bytes[bytes.size() / 2 + 20] ^= 0x10;
    std::string why;
    CHECK(tetseg::load_asset(bytes.data(), bytes.size(), asset, &why) ==
          tetseg::Status::kPayloadChecksum);
    CHECK(std::string(tetseg::to_string(tetseg::Status::kPayloadChecksum)) == "payload checksum");
    CHECK_FALSE(why.empty());
  }
  SECTION("A truncated file is a payload size failure.") {
    CHECK(tetseg::load_asset(bytes.data(), bytes.size() - 1, asset) ==
          tetseg::Status::kPayloadSize);
  }
  SECTION("A file that does not exist is an i/o error.") {
    CHECK(tetseg::load_asset_file("/nonexistent/asset.tetseg", asset) == tetseg::Status::kIoError);
  }
  SECTION("A newer minor version is refused.") {
    tetseg::test::put_le(bytes, tetseg::test::kMinorAt, tetseg::format::kVersionMinor + 1, 2);
    tetseg::test::reseal_header(bytes);
    CHECK(tetseg::load_asset(bytes.data(), bytes.size(), asset) ==
          tetseg::Status::kUnsupportedVersion);
  }
  CHECK(asset.empty());
  CHECK(asset.cluster_count() == 0);
  CHECK(asset.node_count() == 0);
}
