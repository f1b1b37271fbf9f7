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
  kTooShort,            ///< fewer than kEnvelopeBytes bytes
  kBadMagic,            ///< not a tetseg asset
  kUnsupportedVersion,  ///< major differs, minor is newer, or unknown header size / flags
  kHeaderChecksum,      ///< header bytes corrupted (CRC-32C of envelope bytes 0..31)
  kPayloadSize,         ///< payload shorter than the header says, or trailing bytes
  kPayloadChecksum,     ///< payload bytes corrupted (CRC-32C)
  kDecodeFailed,        ///< checksum fine but it does not decode (sizes that do not fit,
                        ///< truncated fields, bytes after the last field, out of memory)
  kInvalidContent,      ///< a count over a documented limit, or a validation rule broken
  kIoError,             ///< the file could not be opened or read
};

/// Short stable name of a status, e.g. "payload checksum". Never null.
const char* to_string(Status status) noexcept;

/// The oldest minor version of format 1 that holds `asset` (docs/format.md, "Versioning"): 2
/// when it stores anything of 1.2 (a body kind other than kTet, a detector form other than
/// kTetPoint, detector terms, bone names, or a cluster's term range or rest position), else 0
/// when every detector is in node form without a tet id and no cluster has a flag, else 1.
std::uint16_t minor_version_needed(const Asset& asset) noexcept;

/// Serialises `asset` (envelope + payload) into bytes, as version
/// 1.`minor_version_needed(asset)`, so an asset that needs nothing new stays readable by 1.0
/// readers. Deterministic: equal assets give equal bytes, and `write_asset` of an asset read from
/// bytes `b` gives `b` again. Does not validate; call `validate` first when the asset is built by
/// hand (an invalid asset is written, and then refused by `read_asset`). Throws std::bad_alloc
/// only. Thread-safe.
std::vector<std::uint8_t> write_asset(const Asset& asset);

/// Parses and validates `size` bytes at `data` into `out`. Safe on untrusted input: reads
/// only `[data, data + size)`, and allocates at most a small multiple of `size` (every
/// vector or string size is checked against the remaining bytes first). On failure `out` is
/// left empty and `detail`, when given, receives a one-line explanation; on success `detail`
/// is cleared. The caller keeps ownership of `data`. Thread-safe; never throws.
Status read_asset(const std::uint8_t* data, std::size_t size, Asset& out,
                  std::string* detail = nullptr) noexcept;

/// The format version an asset's envelope declares. Returns false when `size` is shorter than
/// the envelope or the magic is wrong; checks nothing else (call `read_asset` for that).
bool peek_version(const std::uint8_t* data, std::size_t size, std::uint16_t& major,
                  std::uint16_t& minor) noexcept;

/// Reads a whole file and calls `read_asset`. Returns kIoError (and an empty `out`) when the
/// file cannot be opened or read (`detail`: "cannot open file" or "read error"; callers name
/// the file). The runtime's load_asset_file is this function. Thread-safe; never throws.
Status read_asset_file(const std::string& path, Asset& out, std::string* detail = nullptr) noexcept;

/// Semantic validation alone (what `read_asset` checks after decoding; the full rule list
/// is in docs/format.md, "Validation rules"): counts within the documented limits, indices
/// in range, clusters and loops contiguous, clusters partition the triangles, BVHs are
/// trees whose leaves cover each cluster once, detectors well formed (node form: an interior
/// node; point form: four distinct ids, barycentric weights; 1.2 detector terms: contiguous,
/// indices in range and distinct, weights summing to 1), known cluster flags only, loop edges
/// on the surface, floats finite, provenance keys sorted. Returns kOk or kInvalidContent (with the
/// first broken rule in `detail`). Memory is proportional to the asset's vectors, never to
/// `node_count`. Thread-safe; never throws.
Status validate(const Asset& asset, std::string* detail = nullptr) noexcept;

}  // namespace tetseg::format
