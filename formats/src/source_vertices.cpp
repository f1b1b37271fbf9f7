#include "tetseg/format/source_vertices.hpp"

#include <algorithm>

namespace tetseg::format {

std::size_t source_vertex_count(const Asset& asset) noexcept {
  return asset.source_vertex_nodes.empty() ? asset.node_count : asset.source_vertex_nodes.size();
}

GatherStatus gather_node_positions(const Asset& asset, const double* source_xyz,
                                   std::size_t source_count, double* out) noexcept {
  if (source_count != source_vertex_count(asset)) return GatherStatus::kSizeMismatch;
  if (source_count > 0 && (source_xyz == nullptr || out == nullptr))
    return GatherStatus::kNullInput;
  const std::vector<std::uint32_t>& map = asset.source_vertex_nodes;
  if (map.empty()) {
    std::copy(source_xyz, source_xyz + 3 * source_count, out);
    return GatherStatus::kOk;
  }
  for (std::size_t i = 0; i < source_count; ++i)
    std::copy(source_xyz + 3 * i, source_xyz + 3 * i + 3, out + 3 * std::size_t(map[i]));
  return GatherStatus::kOk;
}

}  // namespace tetseg::format
