#include "crc32c.hpp"

#include <array>

namespace tetseg::format::detail {
namespace {

constexpr std::uint32_t kPolynomial = 0x82F63B78u;  // reflected Castagnoli polynomial

using Tables = std::array<std::array<std::uint32_t, 256>, 8>;

// Slicing-by-8 tables: tables[0] is the classic byte table; tables[k][b] is the CRC of byte
// b followed by k zero bytes.
constexpr Tables make_tables() {
  Tables t{};
  for (std::uint32_t b = 0; b < 256; ++b) {
    std::uint32_t c = b;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? (c >> 1) ^ kPolynomial : c >> 1;
    t[0][b] = c;
  }
  for (std::uint32_t b = 0; b < 256; ++b) {
    for (std::size_t k = 1; k < 8; ++k) t[k][b] = (t[k - 1][b] >> 8) ^ t[0][t[k - 1][b] & 0xFFu];
  }
  return t;
}

constexpr Tables kTables = make_tables();

}  // namespace

std::uint32_t crc32c(const std::uint8_t* data, std::size_t size) noexcept {
  std::uint32_t crc = 0xFFFFFFFFu;
  std::size_t i = 0;
  // Eight bytes at a time, assembled explicitly little-endian so the result does not depend
  // on the host byte order or alignment.
  for (; i + 8 <= size; i += 8) {
    const std::uint32_t lo =
        crc ^ (std::uint32_t(data[i]) | std::uint32_t(data[i + 1]) << 8 |
               std::uint32_t(data[i + 2]) << 16 | std::uint32_t(data[i + 3]) << 24);
    const std::uint32_t hi = std::uint32_t(data[i + 4]) | std::uint32_t(data[i + 5]) << 8 |
                             std::uint32_t(data[i + 6]) << 16 | std::uint32_t(data[i + 7]) << 24;
    crc = kTables[7][lo & 0xFFu] ^ kTables[6][(lo >> 8) & 0xFFu] ^ kTables[5][(lo >> 16) & 0xFFu] ^
          kTables[4][lo >> 24] ^ kTables[3][hi & 0xFFu] ^ kTables[2][(hi >> 8) & 0xFFu] ^
          kTables[1][(hi >> 16) & 0xFFu] ^ kTables[0][hi >> 24];
  }
  for (; i < size; ++i) crc = (crc >> 8) ^ kTables[0][(crc ^ data[i]) & 0xFFu];
  return crc ^ 0xFFFFFFFFu;
}

}  // namespace tetseg::format::detail
