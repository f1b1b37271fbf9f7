// Round trips, determinism, the envelope's byte table and the committed golden asset.
#include <catch2/catch.hpp>

#include <cstdio>
#include <fstream>
#include <set>
#include <thread>

#include "format/test_assets.hpp"

using namespace tetseg::format;
using namespace tetseg::test;

TEST_CASE("The checksum is CRC-32C", "[format]") {
  SECTION("The reference bitwise implementation gives the published check value.") {
    const std::string check = "123456789";
    REQUIRE(crc32c_bitwise(reinterpret_cast<const std::uint8_t*>(check.data()), check.size()) ==
            0xE3069283u);
  }
  SECTION("The envelope's checksums equal CRC-32C of the payload and of the header.") {
    for (const Asset& a : {make_octahedron_asset(), make_cube_asset(5)}) {
      const auto bytes = write_asset(a);
      REQUIRE(bytes.size() > kHeaderBytes);
      CHECK(get_le(bytes, kPayloadCrcAt, 4) ==
            crc32c_bitwise(bytes.data() + kHeaderBytes, bytes.size() - kHeaderBytes));
      CHECK(get_le(bytes, kHeaderCrcAt, 4) == crc32c_bitwise(bytes.data(), kHeaderCrcAt));
    }
  }
}

TEST_CASE("The envelope follows the documented byte table", "[format]") {
  const auto bytes = write_asset(make_octahedron_asset());
  REQUIRE(kEnvelopeBytes == kHeaderBytes);
  const std::uint8_t magic[8] = {0x89, 'T', 'S', 'G', 0x0D, 0x0A, 0x1A, 0x0A};
  CHECK(std::equal(magic, magic + 8, bytes.begin()));
  CHECK(get_le(bytes, kMajorAt, 2) == kVersionMajor);
  CHECK(get_le(bytes, kMinorAt, 2) == kVersionMinor);
  CHECK(get_le(bytes, kHeaderSizeAt, 4) == kHeaderBytes);
  CHECK(get_le(bytes, kFlagsAt, 4) == 0);
  CHECK(get_le(bytes, kPayloadSizeAt, 8) == bytes.size() - kHeaderBytes);
  SECTION(
      "The payload starts with the little-endian tag and its size tags sit where the "
      "documented field order puts them.") {
    const Asset a = make_octahedron_asset();
    CHECK(bytes[kHeaderBytes] == 1);
    CHECK(get_le(bytes, kHeaderBytes + 1, 4) == a.node_count);
    const auto tags = payload_size_tags(a);
    const std::vector<std::size_t> sizes = {
        a.rest_positions.size(),    a.triangles.size(),         a.triangle_cluster.size(),
        a.clusters.size(),          a.cluster_triangles.size(), a.bvh_nodes.size(),
        a.boundaries.size(),        a.boundary_nodes.size(),    a.provenance.tool_version.size(),
        a.provenance.source.size(), a.provenance.options.size()};
    for (std::size_t i = 0; i < sizes.size(); ++i) {
      CAPTURE(tags[i].first);
      CHECK(get_le(bytes, kHeaderBytes + tags[i].second, 8) == sizes[i]);
    }
    CHECK(tags.back().second == bytes.size() - kHeaderBytes);
  }
}

TEST_CASE("Hand-built assets survive a round trip", "[format]") {
  const Asset a =
      GENERATE(make_octahedron_asset(), make_cube_asset(1), make_cube_asset(4), make_cube_asset(9));
  CAPTURE(a.triangles.size(), a.clusters.size());
  std::string why;
  REQUIRE(validate(a, &why) == Status::kOk);
  INFO(why);

  SECTION("Reading what was written gives an equal asset.") {
    const auto bytes = write_asset(a);
    Asset back;
    REQUIRE(read_asset(bytes.data(), bytes.size(), back, &why) == Status::kOk);
    CHECK(why.empty());
    CHECK(assets_equal(a, back));
  }
  SECTION("Writing twice, or writing a copy or a re-read asset, gives identical bytes.") {
    const auto first = write_asset(a);
    const Asset copy = a;
    CHECK(write_asset(a) == first);
    CHECK(write_asset(copy) == first);
    Asset back;
    REQUIRE(read_asset(first.data(), first.size(), back) == Status::kOk);
    CHECK(write_asset(back) == first);
  }
  SECTION("An asset without rest positions also round-trips.") {
    Asset stripped = a;
    stripped.rest_positions.clear();
    const auto bytes = write_asset(stripped);
    Asset back;
    REQUIRE(read_asset(bytes.data(), bytes.size(), back) == Status::kOk);
    CHECK(assets_equal(stripped, back));
    CHECK(bytes.size() == write_asset(a).size() - 24 * a.node_count);
  }
  SECTION("Reading replaces whatever the output asset held before.") {
    const auto bytes = write_asset(a);
    Asset back = make_cube_asset(2);
    REQUIRE(read_asset(bytes.data(), bytes.size(), back) == Status::kOk);
    CHECK(assets_equal(a, back));
  }
}

TEST_CASE("Every status has a distinct stable name", "[format]") {
  std::set<std::string> names;
  const Status all[] = {Status::kOk,
                        Status::kTooShort,
                        Status::kBadMagic,
                        Status::kUnsupportedVersion,
                        Status::kHeaderChecksum,
                        Status::kPayloadSize,
                        Status::kPayloadChecksum,
                        Status::kDecodeFailed,
                        Status::kInvalidContent,
                        Status::kIoError};
  for (Status s : all) {
    REQUIRE(to_string(s) != nullptr);
    names.insert(to_string(s));
  }
  CHECK(names.size() == std::size(all));
  CHECK(std::string(to_string(Status::kPayloadChecksum)) == "payload checksum");
  CHECK(to_string(static_cast<Status>(200)) != nullptr);
}

TEST_CASE("The golden asset of version 1.0 still loads with its original content",
          "[format][golden]") {
  const std::string path = golden_path();
  Asset loaded;
  std::string why;
  REQUIRE(read_asset_file(path, loaded, &why) == Status::kOk);
  INFO(why);
  const Asset expected = make_octahedron_asset();
  CHECK(assets_equal(loaded, expected));
  SECTION("Re-writing the loaded asset reproduces the golden file byte for byte.") {
    CHECK(write_asset(loaded) == read_file(path));
  }
  SECTION(
      "The golden asset is the realistic octahedron: outward winding, interior "
      "detectors, two clusters and one equator loop.") {
    REQUIRE(loaded.clusters.size() == 2);
    CHECK(loaded.boundaries.size() == 1);
    for (const Triangle& t : loaded.triangles) {
      const Vec3& p0 = loaded.rest_positions[t[0]];
      const Vec3 n =
          cross(sub(loaded.rest_positions[t[1]], p0), sub(loaded.rest_positions[t[2]], p0));
      CHECK(dot(n, p0) > 0);  // the octahedron is centred at the origin
    }
    for (const Cluster& c : loaded.clusters) {
      CHECK(c.rest_positive_fraction == 1.0f);  // convex halves seen from inside
      const Vec3& d = loaded.rest_positions[c.detector_node];
      CHECK(std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]) < 1.0);  // strictly inside
    }
  }
}

TEST_CASE("Concurrent reads of shared bytes agree", "[format]") {
  const Asset a = make_cube_asset(6);
  const auto bytes = write_asset(a);
  auto bad = bytes;
  bad[bad.size() / 2] ^= 0x40;
  std::vector<int> ok(4, 0);
  std::vector<int> rejected(4, 0);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 20; ++i) {
        Asset out;
        if (read_asset(bytes.data(), bytes.size(), out) == Status::kOk && assets_equal(out, a))
          ++ok[t];
        if (read_asset(bad.data(), bad.size(), out) == Status::kPayloadChecksum && is_empty(out))
          ++rejected[t];
      }
    });
  }
  for (std::thread& th : threads) th.join();
  for (int t = 0; t < 4; ++t) {
    CHECK(ok[t] == 20);
    CHECK(rejected[t] == 20);
  }
}

TEST_CASE("A missing or unreadable file is an i/o error", "[format]") {
  Asset a = make_octahedron_asset();
  std::string why;
  CHECK(read_asset_file("/nonexistent/dir/none.tetseg", a, &why) == Status::kIoError);
  CHECK(is_empty(a));
  CHECK_FALSE(why.empty());
  CHECK(read_asset_file("/", a) != Status::kOk);  // a directory is not an asset
  CHECK(is_empty(a));
}

// Rebuilds tests/golden/asset-v1.0.tetseg. Hidden; run only when the format version changes:
//   tetseg_tests_format "[.generate]"
TEST_CASE("Generate the golden asset of this version", "[.generate]") {
  const auto bytes = write_asset(make_octahedron_asset());
  const std::string path = std::string(TETSEG_SOURCE_DIR) + "/tests/golden/asset-v" +
                           std::to_string(kVersionMajor) + "." + std::to_string(kVersionMinor) +
                           ".tetseg";
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  REQUIRE(out.good());
  WARN("wrote " << path << " (" << bytes.size() << " bytes)");
}
