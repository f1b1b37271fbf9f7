#pragma once
/// \file
/// Positions in the input file's vertex order (an engine's skinned vertex buffer, split at UV
/// and normal seams) turned into the node positions a surface body steps with
/// (`Asset::source_vertex_nodes`, docs/format.md).

#include <cstddef>
#include <cstdint>

#include "tetseg/format/asset.hpp"

namespace tetseg::format {

enum class GatherStatus : std::uint8_t {
  kOk = 0,
  kNullInput,     ///< a null pointer with a non-zero count
  kSizeMismatch,  ///< source_count differs from the asset's source vertex count
};

/// Vertices of the input file the asset was built from: source_vertex_nodes.size(), or
/// node_count when the asset has no map (node i is vertex i).
std::size_t source_vertex_count(const Asset& asset) noexcept;

/// Writes `out` (node_count x 3 doubles) from `source_xyz` (source_count x 3 doubles, in the
/// input file's vertex order): node source_vertex_nodes[i] takes source vertex i (copies of
/// one node should carry equal positions; the last copy in file order wins), or without a map
/// a plain copy. For an asset that passed validation (every node reached). kSizeMismatch when
/// source_count != source_vertex_count(asset), and then `out` is untouched. Never throws,
/// never allocates.
GatherStatus gather_node_positions(const Asset& asset, const double* source_xyz,
                                   std::size_t source_count, double* out) noexcept;

}  // namespace tetseg::format
