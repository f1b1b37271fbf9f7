#pragma once
/// \file
/// The cereal payload of an asset (field order in docs/format.md). Internal to
/// tetseg::format: cereal never appears in a public header.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/format/asset_io.hpp"

namespace tetseg::format::detail {

/// Exact size in bytes of the payload of `asset` in format 1.`minor`.
std::size_t payload_bytes(const Asset& asset, std::uint16_t minor);

/// Appends the payload of `asset` in format 1.`minor` (0, 1 or 2) to `out`. Deterministic. In
/// 1.0, a cluster's detector is stored as `detector.nodes[0]` (the caller checks that the
/// asset needs no more, minor_version_needed). Throws std::bad_alloc only.
void encode_payload(const Asset& asset, std::uint16_t minor, std::vector<std::uint8_t>& out);

/// Decodes exactly `size` bytes at `data`, a payload of format 1.`minor`, into `out` (which
/// must be empty). A 1.0 detector node n becomes DetectorPoint::at_node(n). Every vector or
/// string size is checked against the bytes that remain before anything is allocated.
/// Returns kOk; kDecodeFailed (truncated, trailing bytes, wrong endianness tag) or
/// kInvalidContent (a count over a documented limit), with a one-line `detail`.
/// Never throws.
Status decode_payload(const std::uint8_t* data, std::size_t size, std::uint16_t minor, Asset& out,
                      std::string& detail) noexcept;

}  // namespace tetseg::format::detail
