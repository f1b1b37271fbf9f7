// Frame-sequence files: round trip, and hostile input never crashes the reader.

#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>

#include "tetseg/runtime/frames.hpp"

using namespace tetseg;

namespace {

FrameSequence sample() {
  FrameSequence f;
  f.node_count = 3;
  f.frame_count = 2;
  for (int i = 0; i < 18; ++i) f.positions.push_back(0.25 * i - 1.0);
  return f;
}

FramesStatus read_copy(const std::vector<std::uint8_t>& bytes, std::size_t size,
                       FrameSequence& out) {
  // A fresh exact-size allocation per call, so sanitizers see any overrun.
  std::unique_ptr<std::uint8_t[]> copy(new std::uint8_t[size + 1]);
  if (size > 0) std::memcpy(copy.get(), bytes.data(), size);
  return read_frames(copy.get(), size, out);
}

void put_u32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) b[at + k] = static_cast<std::uint8_t>(v >> (8 * k));
}

}  // namespace

TEST_CASE("A frame sequence survives a write and read round trip", "[frames]") {
  const FrameSequence f = sample();
  const std::vector<std::uint8_t> bytes = write_frames(f);
  REQUIRE(bytes.size() == kFramesHeaderBytes + 18 * 8);
  CHECK(std::memcmp(bytes.data(), "TSFRAMES", 8) == 0);
  CHECK(bytes[8] == 1);   // version, little-endian
  CHECK(bytes[12] == 3);  // node_count
  CHECK(bytes[16] == 2);  // frame_count
  FrameSequence g;
  REQUIRE(read_frames(bytes.data(), bytes.size(), g) == FramesStatus::kOk);
  CHECK(g.node_count == 3);
  CHECK(g.frame_count == 2);
  CHECK(g.positions == f.positions);
  CHECK(g.frame(1)[0] == f.positions[9]);
}

TEST_CASE("Every truncated prefix of a frame file is rejected without a crash",
          "[frames][hostile]") {
  const std::vector<std::uint8_t> bytes = write_frames(sample());
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    CAPTURE(n);
    FrameSequence out;
    const FramesStatus s = read_copy(bytes, n, out);
    CHECK(s == (n < kFramesHeaderBytes ? FramesStatus::kTooShort : FramesStatus::kSizeMismatch));
    CHECK(out.positions.empty());
  }
  SECTION("Trailing bytes are rejected.") {
    std::vector<std::uint8_t> longer = bytes;
    longer.push_back(0);
    FrameSequence out;
    CHECK(read_frames(longer.data(), longer.size(), out) == FramesStatus::kSizeMismatch);
  }
}

TEST_CASE("Flipped header bytes give distinct statuses and no crash", "[frames][hostile]") {
  const std::vector<std::uint8_t> bytes = write_frames(sample());
  for (std::size_t i = 0; i < kFramesHeaderBytes; ++i) {
    for (std::uint8_t mask : {0x01, 0x80, 0xff}) {
      std::vector<std::uint8_t> b = bytes;
      b[i] ^= mask;
      CAPTURE(i, int(mask));
      FrameSequence out;
      const FramesStatus s = read_copy(b, b.size(), out);
      CHECK(s != FramesStatus::kOk);
      if (i < 8) CHECK(s == FramesStatus::kBadMagic);
      if (i >= 8 && i < 12) CHECK(s == FramesStatus::kUnsupportedVersion);
    }
  }
  SECTION("Huge counts are rejected before allocating.") {
    std::vector<std::uint8_t> b = bytes;
    put_u32(b, 12, 0xffffffffu);
    FrameSequence out;
    CHECK(read_frames(b.data(), b.size(), out) == FramesStatus::kBadHeader);
    put_u32(b, 12, 1u << 26);
    put_u32(b, 16, 0xffffffffu);
    CHECK(read_frames(b.data(), b.size(), out) == FramesStatus::kSizeMismatch);
    put_u32(b, 16, 0);
    CHECK(read_frames(b.data(), b.size(), out) == FramesStatus::kBadHeader);
  }
}

TEST_CASE("Non-finite positions are rejected", "[frames][hostile]") {
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    FrameSequence f = sample();
    f.positions[7] = bad;
    const std::vector<std::uint8_t> bytes = write_frames(f);
    FrameSequence out;
    CHECK(read_frames(bytes.data(), bytes.size(), out) == FramesStatus::kNonFinite);
    CHECK(out.positions.empty());
  }
  SECTION("Payload byte flips never crash and either decode or report non-finite values.") {
    const std::vector<std::uint8_t> bytes = write_frames(sample());
    for (std::size_t i = kFramesHeaderBytes; i < bytes.size(); ++i) {
      std::vector<std::uint8_t> b = bytes;
      b[i] ^= 0xff;
      FrameSequence out;
      const FramesStatus s = read_copy(b, b.size(), out);
      CHECK((s == FramesStatus::kOk || s == FramesStatus::kNonFinite));
    }
  }
}

TEST_CASE("A missing frame file is an i/o error", "[frames]") {
  FrameSequence out;
  std::string why;
  CHECK(read_frames_file("/nonexistent/dir/x.frames", out, &why) == FramesStatus::kIoError);
  CHECK_FALSE(why.empty());
}
