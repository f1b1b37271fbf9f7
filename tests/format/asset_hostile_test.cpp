// Hostile input: truncation, trailing bytes, byte flips, versions, payloads that lie about
// sizes. Every buffer handed to the reader is a fresh heap allocation of exactly its length,
// so sanitizers see any read past the end.
#include <catch2/catch.hpp>

#include <memory>

#include "format/support/test_assets.hpp"
#include "tetseg/testing/allocation_probe.hpp"

using namespace tetseg::format;
using namespace tetseg::test;

namespace {

/// Reads a copy of `bytes[0, size)` held in an exactly sized heap block.
Status read_exact(const std::vector<std::uint8_t>& bytes, std::size_t size, Asset& out,
                  std::string* why = nullptr) {
  std::unique_ptr<std::uint8_t[]> block(new std::uint8_t[size]);
  std::copy(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(size), block.get());
  return read_asset(block.get(), size, out, why);
}

Status read_exact(const std::vector<std::uint8_t>& bytes, Asset& out, std::string* why = nullptr) {
  return read_exact(bytes, bytes.size(), out, why);
}

/// A non-empty asset to read into, so tests see that failures really empty it.
Asset dirty() {
  return make_cube_asset(1);
}

}  // namespace

TEST_CASE("Every truncated prefix of a valid asset is rejected", "[format][hostile]") {
  const Asset source =
      GENERATE(make_octahedron_asset(), make_octahedron_asset_v11(), make_cube_asset(2),
               make_surface_octahedron_v12(DetectorForm::kSurfaceWeights),
               make_surface_octahedron_v12(DetectorForm::kBones));
  const auto bytes = write_asset(source);
  SECTION("A prefix shorter than the envelope is too short; a longer one has a short payload.") {
    for (std::size_t len = 0; len < bytes.size(); ++len) {
      CAPTURE(len);
      Asset out = dirty();
      std::string why;
      const Status s = read_exact(bytes, len, out, &why);
      CHECK(s == (len < kHeaderBytes ? Status::kTooShort : Status::kPayloadSize));
      CHECK(is_empty(out));
      CHECK_FALSE(why.empty());
    }
    Asset out;
    CHECK(read_asset(nullptr, 0, out) == Status::kTooShort);
  }
  SECTION("A truncated payload behind a consistent envelope does not decode.") {
    for (std::size_t len = kHeaderBytes; len < bytes.size(); ++len) {
      CAPTURE(len);
      std::vector<std::uint8_t> cut(bytes.begin(),
                                    bytes.begin() + static_cast<std::ptrdiff_t>(len));
      reseal(cut);
      Asset out = dirty();
      Status s;
      std::size_t largest = 0;
      {
        AllocationProbe probe;
        s = read_exact(cut, out);
        largest = probe.largest();
      }
      CHECK(s == Status::kDecodeFailed);
      CHECK(is_empty(out));
      CHECK(largest <= 4 * len + 1024);
    }
  }
}

TEST_CASE("Any payload byte changed behind a consistent envelope is decoded safely",
          "[format][hostile]") {
  // Every payload byte is set to each of a few values and the envelope resealed, so the
  // change reaches the decoder and the validator. Whatever the status, a failure leaves the
  // asset empty, an accepted result re-writes to the same bytes, and no single allocation
  // exceeds a small multiple of the input size. Every layout: 1.0, 1.1 (detector points,
  // weights and flags) and 1.2 (surface bodies, detector terms, bone names).
  const auto good = write_asset(GENERATE(make_octahedron_asset(), make_octahedron_asset_v11(),
                                         make_surface_octahedron_v12(DetectorForm::kSurfaceWeights),
                                         make_surface_octahedron_v12(DetectorForm::kBones)));
  std::size_t accepted = 0;
  std::size_t decode_failed = 0;
  std::size_t invalid = 0;
  for (std::size_t at = kHeaderBytes; at < good.size(); ++at) {
    for (std::uint8_t value : {0x00, 0x01, 0x7F, 0x80, 0xFF}) {
      if (good[at] == value) continue;
      CAPTURE(at, int(value));
      auto b = good;
      b[at] = value;
      reseal(b);
      Asset out = dirty();
      Status s;
      std::size_t largest = 0;
      {
        AllocationProbe probe;
        s = read_exact(b, out);
        largest = probe.largest();
      }
      CHECK(largest <= 4 * b.size() + 1024);
      if (s == Status::kOk) {
        ++accepted;
        CHECK(write_asset(out) == b);
      } else {
        CHECK(is_empty(out));
        CHECK((s == Status::kDecodeFailed || s == Status::kInvalidContent));
        (s == Status::kDecodeFailed ? decode_failed : invalid) += 1;
      }
    }
  }
  // All three outcomes occur: changed coordinates load, changed sizes do not decode, changed
  // indices are invalid.
  CHECK(accepted > 0);
  CHECK(decode_failed > 0);
  CHECK(invalid > 0);
}

TEST_CASE("Bytes after the payload are rejected", "[format][hostile]") {
  const auto bytes = write_asset(make_octahedron_asset());
  for (std::size_t extra : {1u, 7u, 4096u}) {
    CAPTURE(extra);
    auto longer = bytes;
    longer.resize(bytes.size() + extra, 0);
    Asset out = dirty();
    std::string why;
    CHECK(read_exact(longer, out, &why) == Status::kPayloadSize);
    CHECK(why.find("trailing") != std::string::npos);
    CHECK(is_empty(out));
  }
  SECTION("Trailing bytes inside a payload whose size and checksum agree do not decode.") {
    auto longer = bytes;
    longer.push_back(0);
    reseal(longer);
    Asset out;
    CHECK(read_exact(longer, out) == Status::kDecodeFailed);
  }
}

TEST_CASE("Single-byte flips are caught by the documented step", "[format][hostile]") {
  const auto bytes = write_asset(GENERATE(make_octahedron_asset(), make_octahedron_asset_v11(),
                                          make_surface_octahedron_v12(DetectorForm::kBones)));
  struct Range {
    std::size_t begin, end;
    Status expected;
    const char* field;
  };
  // docs/format.md: the version fields are judged before the header checksum, so a flip there
  // is an unsupported version; the size and checksum fields are covered by the header checksum.
  const Range table[] = {
      {0, 8, Status::kBadMagic, "magic"},
      {kMajorAt, kMajorAt + 2, Status::kUnsupportedVersion, "major"},
      {kMinorAt, kMinorAt + 2, Status::kUnsupportedVersion, "minor"},
      {kHeaderSizeAt, kHeaderSizeAt + 4, Status::kUnsupportedVersion, "header size"},
      {kFlagsAt, kFlagsAt + 4, Status::kUnsupportedVersion, "flags"},
      {kPayloadSizeAt, kPayloadSizeAt + 8, Status::kHeaderChecksum, "payload size"},
      {kPayloadCrcAt, kPayloadCrcAt + 4, Status::kHeaderChecksum, "payload checksum"},
      {kHeaderCrcAt, kHeaderCrcAt + 4, Status::kHeaderChecksum, "header checksum"},
      {kHeaderBytes, bytes.size(), Status::kPayloadChecksum, "payload"},
  };
  const std::uint8_t mask = GENERATE(0x01, 0x80, 0xFF);
  for (const Range& r : table) {
    for (std::size_t at = r.begin; at < r.end; ++at) {
      CAPTURE(r.field, at, int(mask));
      auto flipped = bytes;
      flipped[at] ^= mask;
      Asset out = dirty();
      // A minor flipped to another supported minor passes the version check and is caught
      // by the header checksum.
      const bool supported_minor =
          r.begin == kMinorAt && get_le(flipped, kMinorAt, 2) <= kVersionMinor;
      CHECK(read_exact(flipped, out) == (supported_minor ? Status::kHeaderChecksum : r.expected));
      CHECK(is_empty(out));
    }
  }
}

TEST_CASE("Checks run in the documented order", "[format][hostile]") {
  const auto good = write_asset(make_octahedron_asset());
  Asset out;
  SECTION("A short file with a bad magic is too short.") {
    std::vector<std::uint8_t> b(good.begin(), good.begin() + 10);
    b[0] = 'X';
    CHECK(read_exact(b, out) == Status::kTooShort);
  }
  SECTION("A bad magic wins over a bad version and bad checksums.") {
    auto b = good;
    b[0] = 'X';
    b[kMajorAt] = 9;
    b[kHeaderCrcAt] ^= 1;
    b.back() ^= 1;
    CHECK(read_exact(b, out) == Status::kBadMagic);
  }
  SECTION("A bad version wins over a bad header checksum.") {
    auto b = good;
    b[kMajorAt] = 2;
    b[kPayloadSizeAt] ^= 1;
    CHECK(read_exact(b, out) == Status::kUnsupportedVersion);
  }
  SECTION("A bad header checksum wins over a wrong payload size.") {
    auto b = good;
    b.push_back(0);
    b[kHeaderCrcAt] ^= 1;
    CHECK(read_exact(b, out) == Status::kHeaderChecksum);
  }
  SECTION("A wrong payload size wins over a bad payload checksum.") {
    auto b = good;
    b[kHeaderBytes + 3] ^= 1;
    b.pop_back();
    CHECK(read_exact(b, out) == Status::kPayloadSize);
  }
}

TEST_CASE("Versions: major must match and a newer minor is rejected", "[format][hostile]") {
  const auto good = write_asset(make_octahedron_asset());
  auto with = [&](std::size_t at, std::uint64_t value, std::size_t n) {
    auto b = good;
    put_le(b, at, value, n);
    reseal_header(b);
    return b;
  };
  Asset out = dirty();
  std::string why;
  // A reader of 1.N rejects 1.(N+1) by its version status before decoding anything: this is
  // how a 1.0 reader rejects a 1.1 asset (the 1.0 reader's check is this same code).
  CHECK(read_exact(with(kMinorAt, kVersionMinor + 1, 2), out, &why) == Status::kUnsupportedVersion);
  CHECK(why.find("1.3") != std::string::npos);
  CHECK(why.find("reads 1.0 to 1.2") != std::string::npos);
  CHECK(read_exact(with(kMinorAt, 0xFFFF, 2), out) == Status::kUnsupportedVersion);
  CHECK(read_exact(with(kMajorAt, kVersionMajor + 1, 2), out) == Status::kUnsupportedVersion);
  CHECK(read_exact(with(kMajorAt, kVersionMajor - 1, 2), out) == Status::kUnsupportedVersion);
  CHECK(read_exact(with(kHeaderSizeAt, kHeaderBytes + 4, 4), out) == Status::kUnsupportedVersion);
  CHECK(read_exact(with(kFlagsAt, 1, 4), out) == Status::kUnsupportedVersion);
  CHECK(is_empty(out));
  SECTION("Assets of every minor up to this one load, each decoded by its own layout.") {
    Asset back;
    CHECK(read_exact(good, back) == Status::kOk);
    CHECK(assets_equal(back, make_octahedron_asset()));
    const auto v11 = write_asset(make_octahedron_asset_v11());
    REQUIRE(get_le(v11, kMinorAt, 2) == 1);
    CHECK(read_exact(v11, back) == Status::kOk);
    CHECK(assets_equal(back, make_octahedron_asset_v11()));
    const Asset surface = make_surface_octahedron_v12(DetectorForm::kSurfaceWeights);
    const auto v12 = write_asset(surface);
    REQUIRE(get_le(v12, kMinorAt, 2) == 2);
    CHECK(read_exact(v12, back) == Status::kOk);
    CHECK(assets_equal(back, surface));
  }
  SECTION("A 1.1 reader rejects a 1.2 asset by its version status, before decoding.") {
    // The 1.1 reader's check is `minor > kVersionMinor` with kVersionMinor = 1: this same code.
    const auto v12 = write_asset(make_surface_octahedron_v12(DetectorForm::kBones));
    CHECK(get_le(v12, kMinorAt, 2) > 1);
    CHECK(get_le(v12, kMinorAt, 2) <= kVersionMinor);
  }
  SECTION("A payload relabelled with the other minor does not decode (the layouts differ).") {
    CHECK(read_exact(with(kMinorAt, 1, 2), out) == Status::kDecodeFailed);
    auto v11 = write_asset(make_octahedron_asset_v11());
    put_le(v11, kMinorAt, 0, 2);
    reseal_header(v11);
    CHECK(read_exact(v11, out) == Status::kDecodeFailed);
    CHECK(is_empty(out));
    for (std::uint16_t other : {0, 1}) {
      auto v12 = write_asset(make_surface_octahedron_v12(DetectorForm::kSurfaceWeights));
      put_le(v12, kMinorAt, other, 2);
      reseal_header(v12);
      CHECK(read_exact(v12, out) == Status::kDecodeFailed);
    }
    CHECK(read_exact(with(kMinorAt, 2, 2), out) == Status::kDecodeFailed);
    CHECK(is_empty(out));
  }
}

TEST_CASE("Payloads that claim huge vectors are rejected without allocating", "[format][hostile]") {
  const Asset source =
      GENERATE(make_octahedron_asset(), make_surface_octahedron_v12(DetectorForm::kBones));
  const auto good = write_asset(source);
  const auto tags = payload_size_tags(source);
  {
    // Control: the probe does see the decoder's allocations on a valid asset.
    const Asset big = make_cube_asset(12);
    const auto bytes = write_asset(big);
    Asset out;
    AllocationProbe probe;
    REQUIRE(read_exact(bytes, out) == Status::kOk);
    REQUIRE(probe.largest() >= big.rest_positions.size() * sizeof(Vec3));
  }
  for (std::size_t i = 0; i + 1 < tags.size(); ++i) {
    const std::size_t at = kHeaderBytes + tags[i].second;
    const std::size_t left = good.size() - at - 8;  // bytes after this size tag
    for (std::uint64_t claim : {std::uint64_t(1) << 60, ~std::uint64_t(0), std::uint64_t(1) << 32,
                                std::uint64_t(left) + 1}) {
      CAPTURE(tags[i].first, claim);
      auto b = good;
      put_le(b, at, claim, 8);
      reseal(b);
      Asset out = dirty();
      std::string why;
      Status s;
      std::size_t largest = 0;
      {
        AllocationProbe probe;
        s = read_exact(b, out, &why);
        largest = probe.largest();
      }
      CHECK(s == Status::kDecodeFailed);
      CHECK(is_empty(out));
      INFO(why);
      // Nothing bigger than the input itself (plus string slack) was ever requested.
      CHECK(largest <= 2 * good.size() + 256);
    }
  }
}

TEST_CASE("Payload encoding errors with a valid envelope do not decode", "[format][hostile]") {
  const auto good = write_asset(make_octahedron_asset());
  Asset out = dirty();
  SECTION("A big-endian tag is rejected.") {
    auto b = good;
    b[kHeaderBytes] = 0;
    reseal(b);
    CHECK(read_exact(b, out) == Status::kDecodeFailed);
  }
  SECTION("An empty payload is rejected.") {
    std::vector<std::uint8_t> b(good.begin(), good.begin() + kHeaderBytes);
    reseal(b);
    CHECK(read_exact(b, out) == Status::kDecodeFailed);
  }
  CHECK(is_empty(out));
}

TEST_CASE("Counts over the documented limits are invalid content", "[format][hostile]") {
  Asset a = make_octahedron_asset();
  SECTION("More provenance options than the limit.") {
    a.provenance.options.clear();
    for (std::uint32_t i = 0; i <= kMaxProvenanceOptions; ++i) {
      a.provenance.options.emplace_back("k" + std::to_string(100000 + i), "");
    }
  }
  SECTION("A provenance string longer than the limit.") {
    a.provenance.source.assign(kMaxStringBytes + 1, 'x');
  }
  SECTION("An option value longer than the limit.") {
    a.provenance.options.back().second.assign(kMaxStringBytes + 1, 'v');
  }
  SECTION("A node count over the limit.") {
    a.rest_positions.clear();
    a.node_count = kMaxNodes + 1;
  }
  const auto bytes = write_asset(a);
  Asset out = dirty();
  std::string why;
  CHECK(validate(a) == Status::kInvalidContent);
  CHECK(read_exact(bytes, out, &why) == Status::kInvalidContent);
  CHECK(why.find("limit") != std::string::npos);
  CHECK(is_empty(out));
}
