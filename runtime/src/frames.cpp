#include "tetseg/runtime/frames.hpp"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

#include "tetseg/format/asset.hpp"

namespace tetseg {
namespace {

std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) |
         (std::uint32_t(p[3]) << 24);
}

double get_f64(const std::uint8_t* p) noexcept {
  std::uint64_t bits = 0;
  for (int k = 0; k < 8; ++k) bits |= std::uint64_t(p[k]) << (8 * k);
  double d;
  std::memcpy(&d, &bits, sizeof d);
  return d;
}

FramesStatus fail(FramesStatus status, FrameSequence& out, std::string* detail, const char* why) {
  out = FrameSequence{};
  if (detail) *detail = why;
  return status;
}

}  // namespace

const char* to_string(FramesStatus status) noexcept {
  switch (status) {
    case FramesStatus::kOk:
      return "ok";
    case FramesStatus::kTooShort:
      return "too short";
    case FramesStatus::kBadMagic:
      return "bad magic";
    case FramesStatus::kUnsupportedVersion:
      return "unsupported version";
    case FramesStatus::kBadHeader:
      return "bad header";
    case FramesStatus::kSizeMismatch:
      return "size mismatch";
    case FramesStatus::kNonFinite:
      return "non-finite position";
    case FramesStatus::kIoError:
      return "i/o error";
    case FramesStatus::kOutOfMemory:
      return "out of memory";
  }
  return "unknown";
}

FramesStatus read_frames(const std::uint8_t* data, std::size_t size, FrameSequence& out,
                         std::string* detail) noexcept {
  if (!data || size < kFramesHeaderBytes)
    return fail(FramesStatus::kTooShort, out, detail, "shorter than the 24-byte header");
  if (std::memcmp(data, kFramesMagic, 8) != 0)
    return fail(FramesStatus::kBadMagic, out, detail, "not a TSFRAMES file");
  if (get_u32(data + 8) != kFramesVersion)
    return fail(FramesStatus::kUnsupportedVersion, out, detail, "version is not 1");
  const std::uint32_t nodes = get_u32(data + 12), frames = get_u32(data + 16);
  if (nodes == 0 || nodes > format::kMaxNodes || frames == 0 || get_u32(data + 20) != 0)
    return fail(FramesStatus::kBadHeader, out, detail,
                "node_count must be in [1, 2^26], frame_count >= 1, reserved 0");
  // nodes <= 2^26 and frames < 2^32: the product of 24 * nodes * frames fits in 64 bits.
  const std::uint64_t payload = std::uint64_t(24) * nodes * frames;
  if (payload != std::uint64_t(size - kFramesHeaderBytes))
    return fail(FramesStatus::kSizeMismatch, out, detail,
                "payload size differs from 24 * node_count * frame_count");
  try {
    out = FrameSequence{};
    out.positions.resize(std::size_t(payload / 8));
  } catch (...) {
    return fail(FramesStatus::kOutOfMemory, out, detail, "out of memory");
  }
  const std::uint8_t* p = data + kFramesHeaderBytes;
  for (std::size_t i = 0; i < out.positions.size(); ++i, p += 8) {
    const double d = get_f64(p);
    if (!std::isfinite(d))
      return fail(FramesStatus::kNonFinite, out, detail, "NaN or infinite position");
    out.positions[i] = d;
  }
  out.node_count = nodes;
  out.frame_count = frames;
  return FramesStatus::kOk;
}

FramesStatus read_frames_file(const std::string& path, FrameSequence& out,
                              std::string* detail) noexcept {
  try {
    std::ifstream in(path, std::ios::binary);
    if (!in) return fail(FramesStatus::kIoError, out, detail, "cannot open file");
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
    if (in.bad()) return fail(FramesStatus::kIoError, out, detail, "read error");
    return read_frames(bytes.data(), bytes.size(), out, detail);
  } catch (...) {
    return fail(FramesStatus::kOutOfMemory, out, detail, "out of memory while reading");
  }
}

std::vector<std::uint8_t> write_frames(const FrameSequence& frames) {
  std::vector<std::uint8_t> out;
  if (frames.positions.size() != std::size_t(frames.node_count) * frames.frame_count * 3)
    return out;
  out.resize(kFramesHeaderBytes + frames.positions.size() * 8);
  std::uint8_t* p = out.data();
  for (int k = 0; k < 8; ++k) p[k] = static_cast<std::uint8_t>(kFramesMagic[k]);
  const std::uint32_t header[4] = {kFramesVersion, frames.node_count, frames.frame_count, 0};
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) p[8 + 4 * i + k] = static_cast<std::uint8_t>(header[i] >> (8 * k));
  p += kFramesHeaderBytes;
  for (double d : frames.positions) {
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    for (int k = 0; k < 8; ++k) *p++ = static_cast<std::uint8_t>(bits >> (8 * k));
  }
  return out;
}

}  // namespace tetseg
