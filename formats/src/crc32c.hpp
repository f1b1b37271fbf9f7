#pragma once
/// \file
/// CRC-32C (Castagnoli, reflected polynomial 0x82F63B78, initial value and final XOR
/// 0xFFFFFFFF), the checksum of the asset envelope. Internal to tetseg::format.

#include <cstddef>
#include <cstdint>

namespace tetseg::format::detail {

/// CRC-32C of `size` bytes at `data` (may be null when size is 0). The check value of the
/// ASCII string "123456789" is 0xE3069283. Thread-safe, never throws.
std::uint32_t crc32c(const std::uint8_t* data, std::size_t size) noexcept;

}  // namespace tetseg::format::detail
