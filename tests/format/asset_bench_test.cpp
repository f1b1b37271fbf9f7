// Throughput of writing, reading and validating a large asset. Hidden (not part of CI); run:
//   build/tests/tetseg_tests_format "[.bench]"
// It prints timings and checks only correctness, never speed.
#include <catch2/catch.hpp>

#include <chrono>
#include <cstdio>

#include "format/support/test_assets.hpp"

using namespace tetseg::format;
using namespace tetseg::test;

namespace {

template <class F>
double best_ms(int repeats, F&& f) {
  double best = 1e300;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  return best;
}

}  // namespace

TEST_CASE("Benchmark: write, read and validate a cube asset of about a million triangles",
          "[.bench]") {
  const std::uint32_t grid = 300;
  const Asset a = make_cube_asset(grid);
  REQUIRE(validate(a) == Status::kOk);
  std::vector<std::uint8_t> bytes;
  const double write_ms = best_ms(5, [&] { bytes = write_asset(a); });
  Asset back;
  Status status = Status::kOk;
  const double read_ms = best_ms(5, [&] { status = read_asset(bytes.data(), bytes.size(), back); });
  REQUIRE(status == Status::kOk);
  REQUIRE(assets_equal(a, back));
  const double validate_ms = best_ms(5, [&] { status = validate(a); });
  REQUIRE(status == Status::kOk);
  // A flipped last byte stops reading at the payload checksum: this times envelope + CRC-32C.
  auto corrupt = bytes;
  corrupt.back() ^= 1;
  const double crc_ms =
      best_ms(5, [&] { status = read_asset(corrupt.data(), corrupt.size(), back); });
  REQUIRE(status == Status::kPayloadChecksum);
  const double mb = bytes.size() / 1e6;
  std::printf("asset: grid %u, %zu nodes, %zu triangles, %zu clusters, %zu BVH nodes, %.1f MB\n",
              grid, std::size_t(a.node_count), a.triangles.size(), a.clusters.size(),
              a.bvh_nodes.size(), mb);
  std::printf("write_asset            %8.1f ms  %7.0f MB/s\n", write_ms, mb / write_ms * 1e3);
  std::printf("read_asset (all steps) %8.1f ms  %7.0f MB/s\n", read_ms, mb / read_ms * 1e3);
  std::printf("  validate alone       %8.1f ms\n", validate_ms);
  std::printf("  envelope + CRC-32C   %8.1f ms  %7.0f MB/s\n", crc_ms, mb / crc_ms * 1e3);
}
