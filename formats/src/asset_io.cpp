// The envelope (docs/format.md, "Envelope"): written and read byte by byte, little-endian,
// independent of the host byte order.
#include "tetseg/format/asset_io.hpp"

#include <array>
#include <cstdio>
#include <fstream>
#include <iterator>

#include "crc32c.hpp"
#include "payload.hpp"

namespace tetseg::format {
namespace {

constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'T', 'S', 'G', '\r', '\n', 0x1A, '\n'};

// Byte offsets of the envelope fields.
constexpr std::size_t kOffsetMajor = 8;
constexpr std::size_t kOffsetMinor = 10;
constexpr std::size_t kOffsetHeaderSize = 12;
constexpr std::size_t kOffsetFlags = 16;
constexpr std::size_t kOffsetPayloadSize = 20;
constexpr std::size_t kOffsetPayloadChecksum = 28;
constexpr std::size_t kOffsetHeaderChecksum = 32;
static_assert(kOffsetHeaderChecksum + 4 == kEnvelopeBytes, "envelope layout");

/// Flags defined by this version: none. Any set bit is a feature this library does not know.
constexpr std::uint32_t kKnownFlags = 0;

void put_le(std::uint8_t* p, std::uint64_t value, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes; ++i) p[i] = static_cast<std::uint8_t>(value >> (8 * i));
}

std::uint64_t get_le(const std::uint8_t* p, std::size_t bytes) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < bytes; ++i) value |= std::uint64_t(p[i]) << (8 * i);
  return value;
}

std::string hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", static_cast<unsigned>(v));
  return buf;
}

/// Assigns a message without letting an allocation failure escape.
void set_detail(std::string* detail, const std::string& message) noexcept {
  if (detail == nullptr) return;
  try {
    *detail = message;
  } catch (...) {
  }
}

Status read_impl(const std::uint8_t* data, std::size_t size, Asset& out, std::string& why) {
  if (data == nullptr && size != 0) {
    why = "null data";
    return Status::kTooShort;
  }
  if (size < kEnvelopeBytes) {
    why = std::to_string(size) + " bytes, the envelope alone has " + std::to_string(kEnvelopeBytes);
    return Status::kTooShort;
  }
  for (std::size_t i = 0; i < kMagic.size(); ++i) {
    if (data[i] != kMagic[i]) {
      why = "magic byte " + std::to_string(i) + " is " + std::to_string(data[i]);
      return Status::kBadMagic;
    }
  }
  const auto major = static_cast<std::uint16_t>(get_le(data + kOffsetMajor, 2));
  const auto minor = static_cast<std::uint16_t>(get_le(data + kOffsetMinor, 2));
  const auto header_size = static_cast<std::uint32_t>(get_le(data + kOffsetHeaderSize, 4));
  const auto flags = static_cast<std::uint32_t>(get_le(data + kOffsetFlags, 4));
  const std::string reader_version =
      std::to_string(kVersionMajor) + "." + std::to_string(kVersionMinor);
  if (major != kVersionMajor || minor > kVersionMinor) {
    why = "asset version " + std::to_string(major) + "." + std::to_string(minor) +
          ", this library reads " + std::to_string(kVersionMajor) + ".0 to " + reader_version;
    return Status::kUnsupportedVersion;
  }
  if (header_size != kEnvelopeBytes) {
    why = "header size " + std::to_string(header_size) + ", version " + reader_version + " has " +
          std::to_string(kEnvelopeBytes);
    return Status::kUnsupportedVersion;
  }
  if ((flags & ~kKnownFlags) != 0) {
    why = "unknown flags " + hex32(flags);
    return Status::kUnsupportedVersion;
  }
  const auto stored_header_crc =
      static_cast<std::uint32_t>(get_le(data + kOffsetHeaderChecksum, 4));
  const std::uint32_t header_crc = detail::crc32c(data, kOffsetHeaderChecksum);
  if (stored_header_crc != header_crc) {
    why = "header checksum " + hex32(stored_header_crc) + ", computed " + hex32(header_crc);
    return Status::kHeaderChecksum;
  }
  const std::uint64_t payload_size = get_le(data + kOffsetPayloadSize, 8);
  const std::size_t available = size - kEnvelopeBytes;
  if (payload_size != available) {
    why = "header announces a payload of " + std::to_string(payload_size) + " bytes, " +
          std::to_string(available) + " follow the envelope (" +
          (payload_size > available ? "truncated" : "trailing bytes") + ")";
    return Status::kPayloadSize;
  }
  const std::uint8_t* payload = data + kEnvelopeBytes;
  const auto stored_payload_crc =
      static_cast<std::uint32_t>(get_le(data + kOffsetPayloadChecksum, 4));
  const std::uint32_t payload_crc = detail::crc32c(payload, available);
  if (stored_payload_crc != payload_crc) {
    why = "payload checksum " + hex32(stored_payload_crc) + ", computed " + hex32(payload_crc);
    return Status::kPayloadChecksum;
  }
  const Status decoded = detail::decode_payload(payload, available, minor, out, why);
  if (decoded != Status::kOk) return decoded;
  return validate(out, &why);
}

}  // namespace

bool peek_version(const std::uint8_t* data, std::size_t size, std::uint16_t& major,
                  std::uint16_t& minor) noexcept {
  if (data == nullptr || size < kEnvelopeBytes) return false;
  for (std::size_t i = 0; i < kMagic.size(); ++i) {
    if (data[i] != kMagic[i]) return false;
  }
  major = static_cast<std::uint16_t>(get_le(data + kOffsetMajor, 2));
  minor = static_cast<std::uint16_t>(get_le(data + kOffsetMinor, 2));
  return true;
}

const char* to_string(Status status) noexcept {
  switch (status) {
    case Status::kOk:
      return "ok";
    case Status::kTooShort:
      return "too short";
    case Status::kBadMagic:
      return "bad magic";
    case Status::kUnsupportedVersion:
      return "unsupported version";
    case Status::kHeaderChecksum:
      return "header checksum";
    case Status::kPayloadSize:
      return "payload size";
    case Status::kPayloadChecksum:
      return "payload checksum";
    case Status::kDecodeFailed:
      return "decode failed";
    case Status::kInvalidContent:
      return "invalid content";
    case Status::kIoError:
      return "i/o error";
  }
  return "unknown status";
}

std::uint16_t minor_version_needed(const Asset& asset) noexcept {
  // Anything 1.2 stores (also when it is invalid, so the reader refuses it rather than the
  // writer dropping it).
  if (asset.body_kind != BodyKind::kTet || asset.detector_form != DetectorForm::kTetPoint ||
      !asset.detector_terms.empty() || !asset.bone_names.empty() ||
      !asset.source_vertex_nodes.empty())
    return 2;
  std::uint16_t minor = 0;
  for (const Cluster& c : asset.clusters) {
    if (c.detector_term_offset != 0 || c.detector_term_count != 0 ||
        c.detector_rest != std::array<double, 3>{})
      return 2;
    if (!c.detector.is_node() || c.detector.tet != kNoTet || c.flags != 0) minor = 1;
  }
  return minor;
}

std::vector<std::uint8_t> write_asset(const Asset& asset) {
  const std::uint16_t minor = minor_version_needed(asset);
  std::vector<std::uint8_t> bytes(kEnvelopeBytes, 0);
  detail::encode_payload(asset, minor, bytes);
  const std::size_t payload_size = bytes.size() - kEnvelopeBytes;
  std::uint8_t* h = bytes.data();
  for (std::size_t i = 0; i < kMagic.size(); ++i) h[i] = kMagic[i];
  put_le(h + kOffsetMajor, kVersionMajor, 2);
  put_le(h + kOffsetMinor, minor, 2);
  put_le(h + kOffsetHeaderSize, kEnvelopeBytes, 4);
  put_le(h + kOffsetFlags, 0, 4);
  put_le(h + kOffsetPayloadSize, payload_size, 8);
  put_le(h + kOffsetPayloadChecksum, detail::crc32c(h + kEnvelopeBytes, payload_size), 4);
  put_le(h + kOffsetHeaderChecksum, detail::crc32c(h, kOffsetHeaderChecksum), 4);
  return bytes;
}

Status read_asset(const std::uint8_t* data, std::size_t size, Asset& out,
                  std::string* detail) noexcept {
  Status status = Status::kDecodeFailed;
  std::string why;
  try {
    out = Asset{};
    status = read_impl(data, size, out, why);
  } catch (const std::exception& e) {
    // Only an allocation failure can get here; report it as a decode failure.
    status = Status::kDecodeFailed;
    try {
      why = std::string("decoding failed: ") + e.what();
    } catch (...) {
    }
  } catch (...) {
    status = Status::kDecodeFailed;
  }
  if (status != Status::kOk) {
    out = Asset{};
    set_detail(detail, why);
  } else {
    set_detail(detail, "");
  }
  return status;
}

Status read_asset_file(const std::string& path, Asset& out, std::string* detail) noexcept {
  std::vector<std::uint8_t> bytes;
  try {
    out = Asset{};
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      set_detail(detail, "cannot open file");
      return Status::kIoError;
    }
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (in.bad()) {
      set_detail(detail, "read error");
      return Status::kIoError;
    }
  } catch (...) {
    set_detail(detail, "cannot read the file (out of memory or stream failure)");
    return Status::kIoError;
  }
  return read_asset(bytes.data(), bytes.size(), out, detail);
}

}  // namespace tetseg::format
