#pragma once
/// \file
/// Reading and writing assets. Reading is safe on untrusted input: every failure is a status,
/// no exception escapes, and no allocation is sized from the file before it is checked
/// against the bytes that remain.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"

namespace tetseg::format {

/// Bytes of the fixed envelope ahead of the payload; its byte table is in docs/format.md.
inline constexpr std::size_t kEnvelopeBytes = 36;

/// Result of reading an asset. Checks run in this order and stop at the first failure.
enum class Status : std::uint8_t {
  kOk = 0,
  kTooShort,            ///< fewer bytes than the envelope header
  kBadMagic,            ///< not a tetseg asset
  kUnsupportedVersion,  ///< major differs, or minor is newer than this library
  kHeaderChecksum,      ///< header bytes corrupted
  kPayloadSize,         ///< payload shorter than the header says, or trailing bytes
  kPayloadChecksum,     ///< payload bytes corrupted
  kDecodeFailed,        ///< payload checksum fine but it does not decode
  kInvalidContent,      ///< decodes, but indices, counts, partition or floats are invalid
  kIoError,             ///< the file could not be opened or read
};

/// Short stable name of a status, e.g. "payload checksum". Never null.
const char* to_string(Status status) noexcept;

/// Serialises `asset` (envelope + payload) into bytes. Deterministic: equal assets give equal
/// bytes. Does not validate; call `validate` first when the asset is built by hand.
std::vector<std::uint8_t> write_asset(const Asset& asset);

/// Parses and validates `size` bytes at `data` into `out`. On failure `out` is left empty
/// and `detail`, when given, receives a one-line explanation. Thread-safe; never throws.
Status read_asset(const std::uint8_t* data, std::size_t size, Asset& out,
                  std::string* detail = nullptr) noexcept;

/// Reads a whole file and calls `read_asset`. Returns kIoError when the file cannot be read.
Status read_asset_file(const std::string& path, Asset& out, std::string* detail = nullptr) noexcept;

/// Semantic validation alone (what `read_asset` checks after decoding): indices in range,
/// counts within the documented limits, clusters partition the triangles, BVHs well formed,
/// detector nodes not on the surface, floats finite. Returns kOk or kInvalidContent.
Status validate(const Asset& asset, std::string* detail = nullptr) noexcept;

}  // namespace tetseg::format
