#include "tetseg/runtime/asset.hpp"

namespace tetseg {

Status load_asset(const std::uint8_t* data, std::size_t size, Asset& out,
                  std::string* detail) noexcept {
  out.m_data = format::Asset{};
  return format::read_asset(data, size, out.m_data, detail);
}

Status load_asset_file(const std::string& path, Asset& out, std::string* detail) noexcept {
  return format::read_asset_file(path, out.m_data, detail);  // clears out.m_data on failure
}

}  // namespace tetseg
