// Round trips, determinism, the envelope's byte table and the committed golden asset.
#include <catch2/catch.hpp>

#include <cstdio>
#include <fstream>
#include <set>
#include <thread>

#include "format/support/test_assets.hpp"

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
  CHECK(get_le(bytes, kMinorAt, 2) == 0);  // needs nothing of 1.1
  CHECK(get_le(write_asset(make_octahedron_asset_v11()), kMinorAt, 2) == 1);
  CHECK(get_le(write_asset(make_surface_octahedron_v12(DetectorForm::kBones)), kMinorAt, 2) ==
        kVersionMinor);
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
      GENERATE(make_octahedron_asset(), make_cube_asset(1), make_cube_asset(4), make_cube_asset(9),
               make_surface_octahedron_v12(DetectorForm::kSurfaceWeights),
               make_surface_octahedron_v12(DetectorForm::kBones));
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
    CHECK(bytes.size() == write_asset(a).size() - 24 * a.rest_positions.size());
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
      CHECK(c.detector.is_node());
      CHECK(c.detector.tet == kNoTet);
      CHECK(c.flags == 0);
      const Vec3& d = loaded.rest_positions[c.detector.nodes[0]];
      CHECK(std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]) < 1.0);  // strictly inside
    }
  }
}

TEST_CASE("The golden asset of version 1.1 loads with detector points and a flagged cluster",
          "[format][golden]") {
  const std::string path = golden_path(1);
  Asset loaded;
  std::string why;
  REQUIRE(read_asset_file(path, loaded, &why) == Status::kOk);
  INFO(why);
  std::uint16_t major = 0, minor = 0;
  const auto bytes = read_file(path);
  REQUIRE(peek_version(bytes.data(), bytes.size(), major, minor));
  CHECK(major == 1);
  CHECK(minor == 1);
  CHECK(assets_equal(loaded, make_octahedron_asset_v11()));
  CHECK(write_asset(loaded) == bytes);
  REQUIRE(loaded.clusters.size() == 2);
  CHECK_FALSE(loaded.clusters[0].detector.is_node());
  CHECK(loaded.clusters[0].detector.tet == 0);
  CHECK(loaded.clusters[0].flags == 0);
  CHECK(loaded.clusters[1].flags == kClusterOverlapOnly);
  for (const Cluster& c : loaded.clusters) {
    const Vec3 d = detector_position(loaded, c);
    CHECK(std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]) < 1.0);  // strictly inside
    CHECK(c.rest_positive_fraction == 1.0f);
  }
}

TEST_CASE("Writing uses the oldest minor version that holds the asset", "[format]") {
  Asset a = make_octahedron_asset();
  CHECK(minor_version_needed(a) == 0);
  SECTION("A tet id alone needs 1.1.") {
    a.clusters[0].detector.tet = 3;
  }
  SECTION("A flag alone needs 1.1.") {
    a.clusters[1].flags = kClusterOverlapOnly;
  }
  SECTION("A point-form detector needs 1.1, even at a node (weights 1, 0, 0, 0).") {
    a.clusters[0].detector.nodes = {6, 0, 2, 4};
  }
  CHECK(minor_version_needed(a) == 1);
  const auto bytes = write_asset(a);
  CHECK(get_le(bytes, kMinorAt, 2) == 1);
  Asset back;
  std::string why;
  CHECK(read_asset(bytes.data(), bytes.size(), back, &why) == Status::kOk);
  INFO(why);
  CHECK(assets_equal(back, a));
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

// Rebuilds tests/golden/asset-v1.<minor>.tetseg of the current version. Hidden; run only when
// the format version changes (never rewrite an older version's golden file):
//   tetseg_tests_format "[.generate]"
TEST_CASE("Generate the golden assets of this version", "[.generate]") {
  static_assert(kVersionMajor == 1 && kVersionMinor == 2, "add the new version's golden asset");
  const auto [variant, form] =
      GENERATE(std::make_pair(std::string(""), DetectorForm::kSurfaceWeights),
               std::make_pair(std::string("-bones"), DetectorForm::kBones));
  const auto bytes = write_asset(make_surface_octahedron_v12(form));
  const std::string path = golden_path(kVersionMinor, variant);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  REQUIRE(out.good());
  WARN("wrote " << path << " (" << bytes.size() << " bytes)");
}
