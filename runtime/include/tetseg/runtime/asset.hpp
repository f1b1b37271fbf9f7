#pragma once
/// \file
/// Loading an asset into the runtime. An `Asset` is immutable after loading and may be shared
/// by any number of colliders on any threads.

#include <cstddef>
#include <cstdint>
#include <string>

#include "tetseg/format/asset.hpp"
#include "tetseg/format/asset_io.hpp"

namespace tetseg {

using Status = format::Status;
using format::to_string;

/// A validated asset. Read-only accessors; cheap to share by const reference.
class Asset {
 public:
  Asset() = default;
  const format::Asset& data() const noexcept { return m_data; }
  std::uint32_t node_count() const noexcept { return m_data.node_count; }
  std::size_t triangle_count() const noexcept { return m_data.triangles.size(); }
  std::size_t cluster_count() const noexcept { return m_data.clusters.size(); }
  bool empty() const noexcept { return m_data.triangles.empty(); }

 private:
  friend Status load_asset(const std::uint8_t*, std::size_t, Asset&, std::string*) noexcept;
  friend Status load_asset_file(const std::string&, Asset&, std::string*) noexcept;
  format::Asset m_data;
};

/// Loads and validates an asset from memory. Safe on untrusted input; never throws.
/// On failure `out` is empty and `detail` (optional) explains.
Status load_asset(const std::uint8_t* data, std::size_t size, Asset& out,
                  std::string* detail = nullptr) noexcept;

/// Loads and validates an asset file. Returns Status::kIoError when it cannot be read.
Status load_asset_file(const std::string& path, Asset& out, std::string* detail = nullptr) noexcept;

}  // namespace tetseg
