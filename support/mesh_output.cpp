#include "mesh_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "mesh_io.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {
namespace {

// Tableau 20 reordered so the first ten are the strong colours.
constexpr Rgb kPalette[20] = {
    {31, 119, 180},  {255, 127, 14},  {44, 160, 44},   {214, 39, 40},   {148, 103, 189},
    {140, 86, 75},   {227, 119, 194}, {127, 127, 127}, {188, 189, 34},  {23, 190, 207},
    {174, 199, 232}, {255, 187, 120}, {152, 223, 138}, {255, 152, 150}, {197, 176, 213},
    {196, 156, 148}, {247, 182, 210}, {199, 199, 199}, {219, 219, 141}, {158, 218, 229},
};

// Samples of a viridis-like map at 0, 1/8, ..., 1.
constexpr double kScalarMap[9][3] = {
    {68, 1, 84},    {71, 44, 122}, {59, 81, 139},  {44, 113, 142}, {33, 144, 141},
    {39, 173, 129}, {92, 200, 99}, {170, 220, 50}, {253, 231, 37},
};

/// Nodes the pictures use, in ascending id, and the map node id -> point index.
struct UsedNodes {
  std::vector<std::uint32_t> ids;
  std::vector<std::uint32_t> index;  // per node id, or UINT32_MAX
};

UsedNodes used_nodes(const format::Asset& asset, bool with_detectors) {
  UsedNodes used;
  const std::size_t n = asset.rest_positions.size();
  std::vector<std::uint8_t> flag(n, 0);
  auto mark = [&](std::uint32_t v) {
    if (v < n) flag[v] = 1;
  };
  for (const auto& t : asset.triangles)
    for (std::uint32_t v : t) mark(v);
  for (std::uint32_t v : asset.boundary_nodes) mark(v);
  if (with_detectors)
    for (const auto& c : asset.clusters)
      if (asset.detector_form == format::DetectorForm::kTetPoint && c.detector.is_node())
        mark(c.detector.nodes[0]);
  used.index.assign(n, UINT32_MAX);
  for (std::uint32_t v = 0; v < n; ++v)
    if (flag[v]) {
      used.index[v] = static_cast<std::uint32_t>(used.ids.size());
      used.ids.push_back(v);
    }
  return used;
}

}  // namespace

Rgb palette_color(std::uint32_t index) noexcept {
  return kPalette[index % 20];
}

Rgb scalar_color(double value) noexcept {
  if (std::isnan(value)) return {128, 128, 128};
  const double x = std::clamp(value, 0.0, 1.0) * 8.0;
  const int i = std::min(7, static_cast<int>(x));
  const double f = x - i;
  Rgb out{};
  for (int k = 0; k < 3; ++k)
    out[k] = static_cast<std::uint8_t>(
        std::lround(kScalarMap[i][k] * (1.0 - f) + kScalarMap[i + 1][k] * f));
  return out;
}

void require_rest_positions(const format::Asset& asset, const std::string& source) {
  if (asset.rest_positions.empty())
    throw ToolError(kExitBadInput, source,
                    "the asset has no rest positions (built with --no-rest-positions); "
                    "rebuild it with them to draw it");
  if (asset.rest_positions.size() != asset.node_count)
    throw ToolError(kExitBadInput, source, "rest positions do not match the node count");
}

std::string asset_to_vtu(const format::Asset& asset, const std::string& source) {
  require_rest_positions(asset, source);
  const UsedNodes used = used_nodes(asset, true);
  io::UnstructuredGrid grid;
  io::DataArray node_id{"node_id", "UInt32", {}};
  for (std::uint32_t v : used.ids) {
    grid.points.push_back(asset.rest_positions[v]);
    node_id.values.push_back(v);
  }
  // Point-form detectors: extra points after the used nodes.
  std::vector<std::uint32_t> detector_point(asset.clusters.size(), UINT32_MAX);
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    const format::DetectorPoint& d = asset.clusters[c].detector;
    if (asset.detector_form == format::DetectorForm::kTetPoint && d.is_node()) {
      detector_point[c] = used.index[d.nodes[0]];
    } else {
      detector_point[c] = static_cast<std::uint32_t>(grid.points.size());
      grid.points.push_back(format::rest_detector_position(asset, asset.clusters[c]));
      node_id.values.push_back(UINT32_MAX);
    }
  }
  grid.point_data.push_back(std::move(node_id));
  io::DataArray cluster{"cluster", "Int32", {}}, kind{"kind", "UInt8", {}},
      boundary{"boundary", "Int32", {}}, visibility{"rest_positive_fraction", "Float32", {}},
      overlap_only{"overlap_only", "UInt8", {}}, detector_tet{"detector_tet", "Int32", {}};
  auto add_cell = [&](std::uint8_t type, std::vector<std::uint32_t> points, double cluster_id,
                      double kind_id, double boundary_id, double fraction) {
    grid.cell_types.push_back(type);
    grid.cells.push_back(std::move(points));
    cluster.values.push_back(cluster_id);
    kind.values.push_back(kind_id);
    boundary.values.push_back(boundary_id);
    visibility.values.push_back(fraction);
    const bool in_cluster = cluster_id >= 0 && cluster_id < asset.clusters.size();
    overlap_only.values.push_back(
        in_cluster && (asset.clusters[static_cast<std::size_t>(cluster_id)].flags &
                       format::kClusterOverlapOnly)
            ? 1.0
            : 0.0);
    const std::uint32_t tet =
        kind_id == 2 ? asset.clusters[static_cast<std::size_t>(cluster_id)].detector.tet
                     : format::kNoTet;
    detector_tet.values.push_back(tet == format::kNoTet ? -1.0 : static_cast<double>(tet));
  };
  const std::size_t det_count = asset.clusters.size();
  for (std::size_t t = 0; t < asset.triangles.size(); ++t) {
    const auto& tri = asset.triangles[t];
    const std::uint32_t c = asset.triangle_cluster[t];
    add_cell(5, {used.index[tri[0]], used.index[tri[1]], used.index[tri[2]]}, c, 0, -1,
             c < det_count ? asset.clusters[c].rest_positive_fraction : 0.0f);
  }
  for (std::size_t l = 0; l < asset.boundaries.size(); ++l) {
    const auto& loop = asset.boundaries[l];
    std::vector<std::uint32_t> points;
    for (std::uint32_t i = 0; i < loop.node_count; ++i)
      points.push_back(used.index[asset.boundary_nodes[loop.node_offset + i]]);
    points.push_back(used.index[asset.boundary_nodes[loop.node_offset]]);  // closed
    add_cell(4, std::move(points), -1, 1, static_cast<double>(l), 0.0);
  }
  for (std::size_t c = 0; c < det_count; ++c) {
    add_cell(1, {detector_point[c]}, static_cast<double>(c), 2, -1,
             asset.clusters[c].rest_positive_fraction);
  }
  grid.cell_data = {std::move(cluster),    std::move(kind),         std::move(boundary),
                    std::move(visibility), std::move(overlap_only), std::move(detector_tet)};
  return io::vtu_text(grid);
}

std::string asset_to_ply(const format::Asset& asset, const std::string& source) {
  require_rest_positions(asset, source);
  const UsedNodes used = used_nodes(asset, false);
  io::PlyOutMesh ply;
  ply.comment = "tetseg asset surface: face colour = cluster, edges = segment boundaries";
  for (std::uint32_t v : used.ids) ply.vertices.push_back(asset.rest_positions[v]);
  ply.face_properties = {
      {"red", "uchar", {}}, {"green", "uchar", {}}, {"blue", "uchar", {}}, {"cluster", "int", {}}};
  for (std::size_t t = 0; t < asset.triangles.size(); ++t) {
    const auto& tri = asset.triangles[t];
    ply.triangles.push_back({used.index[tri[0]], used.index[tri[1]], used.index[tri[2]]});
    const Rgb c = palette_color(asset.triangle_cluster[t]);
    for (int k = 0; k < 3; ++k) ply.face_properties[k].values.push_back(c[k]);
    ply.face_properties[3].values.push_back(asset.triangle_cluster[t]);
  }
  ply.edge_properties = {{"red", "uchar", {}}, {"green", "uchar", {}}, {"blue", "uchar", {}}};
  for (const auto& loop : asset.boundaries) {
    for (std::uint32_t i = 0; i < loop.node_count; ++i) {
      const std::uint32_t a = asset.boundary_nodes[loop.node_offset + i];
      const std::uint32_t b = asset.boundary_nodes[loop.node_offset + (i + 1) % loop.node_count];
      ply.edges.push_back({used.index[a], used.index[b]});
      for (auto& channel : ply.edge_properties) channel.values.push_back(0);  // black
    }
  }
  return io::ply_text(ply);
}

std::string detector_text(const format::Asset& asset, const format::Cluster& cluster) {
  const format::DetectorPoint& d = cluster.detector;
  char buf[160];
  if (asset.detector_form != format::DetectorForm::kTetPoint) {
    const bool bones = asset.detector_form == format::DetectorForm::kBones;
    std::string text = bones ? "bones" : "weights";
    const format::DetectorTerm* terms = asset.detector_terms.data() + cluster.detector_term_offset;
    for (std::uint32_t i = 0; i < cluster.detector_term_count && i < 4; ++i) {
      std::snprintf(buf, sizeof buf, " %s%u:%.3g", bones ? "" : "n", terms[i].index,
                    terms[i].weight);
      text += buf;
    }
    if (cluster.detector_term_count > 4)
      text += " (+" + std::to_string(cluster.detector_term_count - 4) + " terms)";
    if (cluster.detector_term_count == 0) text += " none";
    return text;
  }
  if (d.is_node()) {
    std::snprintf(buf, sizeof buf, "node %u", static_cast<unsigned>(d.nodes[0]));
  } else {
    const std::string tet = d.tet == format::kNoTet ? "?" : std::to_string(d.tet);
    std::snprintf(buf, sizeof buf, "tet %s (%u %u %u %u) w %.4g %.4g %.4g %.4g", tet.c_str(),
                  static_cast<unsigned>(d.nodes[0]), static_cast<unsigned>(d.nodes[1]),
                  static_cast<unsigned>(d.nodes[2]), static_cast<unsigned>(d.nodes[3]),
                  d.weights[0], d.weights[1], d.weights[2], d.weights[3]);
  }
  return buf;
}

}  // namespace tetseg::tools
