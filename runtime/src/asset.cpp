#include "tetseg/runtime/asset.hpp"

#include <fstream>
#include <iterator>
#include <vector>

namespace tetseg {

Status load_asset(const std::uint8_t* data, std::size_t size, Asset& out,
                  std::string* detail) noexcept {
  out.m_data = format::Asset{};
  return format::read_asset(data, size, out.m_data, detail);
}

Status load_asset_file(const std::string& path, Asset& out, std::string* detail) noexcept {
  try {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
      if (detail) *detail = "cannot open file";
      out.m_data = format::Asset{};
      return Status::kIoError;
    }
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                    std::istreambuf_iterator<char>());
    if (in.bad()) {
      if (detail) *detail = "read error";
      out.m_data = format::Asset{};
      return Status::kIoError;
    }
    return load_asset(bytes.data(), bytes.size(), out, detail);
  } catch (...) {
    if (detail) *detail = "out of memory while reading";
    out.m_data = format::Asset{};
    return Status::kIoError;
  }
}

}  // namespace tetseg
