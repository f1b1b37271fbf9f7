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

/// Exact size in bytes of the payload of `asset`.
std::size_t payload_bytes(const Asset& asset);

/// Appends the payload of `asset` to `out`. Deterministic. Throws std::bad_alloc only.
void encode_payload(const Asset& asset, std::vector<std::uint8_t>& out);

/// Decodes exactly `size` bytes at `data` into `out` (which must be empty). Every vector or
/// string size is checked against the bytes that remain before anything is allocated.
/// Returns kOk; kDecodeFailed (truncated, trailing bytes, wrong endianness tag) or
/// kInvalidContent (a count over a documented limit), with a one-line `detail`.
/// Never throws.
Status decode_payload(const std::uint8_t* data, std::size_t size, Asset& out,
                      std::string& detail) noexcept;

}  // namespace tetseg::format::detail
