#pragma once
/// \file
/// Visual output of an asset for people: ParaView `.vtu` and MeshLab `.ply` with cluster ids,
/// segment boundaries and detector nodes, and the fixed colour palette every tool shares.
/// Needs the asset's rest positions. Links tetseg::format only.

#include <array>
#include <cstdint>
#include <string>

#include "tetseg/format/asset.hpp"

namespace tetseg::tools {

using Rgb = std::array<std::uint8_t, 3>;

/// Colour of cluster `index` from a fixed 20-colour palette (repeats after 20), so reruns and
/// different tools draw the same cluster in the same colour.
Rgb palette_color(std::uint32_t index) noexcept;

/// Colour for a scalar in [0,1] (a perceptually ordered dark-blue -> yellow map); values
/// outside are clamped, NaN is grey.
Rgb scalar_color(double value) noexcept;

/// Throws ToolError(kExitBadInput, source, ...) when the asset carries no rest positions (built
/// with `--no-rest-positions`): there is nothing to draw.
void require_rest_positions(const format::Asset& asset, const std::string& source);

/// VTK XML UnstructuredGrid (ASCII). Points: the rest positions of the nodes used by surface
/// triangles, boundaries and node-form detectors (renumbered, original id in point data
/// `node_id`), then the rest position of every point-form detector (`node_id` 4294967295).
/// Cells: surface triangles, then one closed poly-line per segment boundary, then one vertex
/// per detector. Cell data: `cluster` (Int32; -1 for boundaries), `kind` (0 triangle,
/// 1 boundary, 2 detector), `boundary` (loop index or -1), `rest_positive_fraction` (of the
/// cell's cluster; 0 for boundaries), `overlap_only` (1 when the cell's cluster is flagged
/// overlap-only, else 0), `detector_tet` (detector cells: the input tet holding the point, -1
/// for a node or an unknown tet; -1 for other cells). Deterministic. Calls
/// require_rest_positions first.
std::string asset_to_vtu(const format::Asset& asset, const std::string& source);

/// ASCII PLY: the surface with per-face colour palette_color(cluster) and a `cluster` face
/// property, plus an `edge` element (black) for every segment-boundary edge. Deterministic.
/// Calls require_rest_positions first.
std::string asset_to_ply(const format::Asset& asset, const std::string& source);

/// One-line human form of a detector: "node 17" for the node form, else
/// "tet 512 (3 9 10 44) w 0.25 0.25 0.25 0.25"; 1.2 forms: "weights n3:0.25 n9:0.75" or
/// "bones 2:0.75 3:0.25" (the first four terms, then "(+N terms)"; "none" without terms).
std::string detector_text(const format::Asset& asset, const format::Cluster& cluster);

}  // namespace tetseg::tools
