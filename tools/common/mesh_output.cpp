#include "mesh_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

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

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

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
    for (const auto& c : asset.clusters) mark(c.detector_node);
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
  const std::size_t tri_count = asset.triangles.size();
  const std::size_t loop_count = asset.boundaries.size();
  const std::size_t det_count = asset.clusters.size();
  const std::size_t cells = tri_count + loop_count + det_count;
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid>\n"
      << "<Piece NumberOfPoints=\"" << used.ids.size() << "\" NumberOfCells=\"" << cells
      << "\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (std::uint32_t v : used.ids) {
    const auto& p = asset.rest_positions[v];
    out << number(p[0]) << ' ' << number(p[1]) << ' ' << number(p[2]) << '\n';
  }
  out << "</DataArray>\n</Points>\n<PointData>\n"
      << "<DataArray type=\"UInt32\" Name=\"node_id\" format=\"ascii\">\n";
  for (std::uint32_t v : used.ids) out << v << '\n';
  out << "</DataArray>\n</PointData>\n<Cells>\n"
      << "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& t : asset.triangles)
    out << used.index[t[0]] << ' ' << used.index[t[1]] << ' ' << used.index[t[2]] << '\n';
  for (const auto& loop : asset.boundaries) {
    for (std::uint32_t i = 0; i < loop.node_count; ++i)
      out << used.index[asset.boundary_nodes[loop.node_offset + i]] << ' ';
    out << used.index[asset.boundary_nodes[loop.node_offset]] << '\n';  // closed
  }
  for (const auto& c : asset.clusters) out << used.index[c.detector_node] << '\n';
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  std::uint64_t offset = 0;
  for (std::size_t t = 0; t < tri_count; ++t) out << (offset += 3) << '\n';
  for (const auto& loop : asset.boundaries) out << (offset += loop.node_count + 1) << '\n';
  for (std::size_t c = 0; c < det_count; ++c) out << (offset += 1) << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tri_count; ++t) out << "5\n";
  for (std::size_t l = 0; l < loop_count; ++l) out << "4\n";
  for (std::size_t c = 0; c < det_count; ++c) out << "1\n";
  out << "</DataArray>\n</Cells>\n<CellData Scalars=\"cluster\">\n"
      << "<DataArray type=\"Int32\" Name=\"cluster\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tri_count; ++t) out << asset.triangle_cluster[t] << '\n';
  for (std::size_t l = 0; l < loop_count; ++l) out << "-1\n";
  for (std::size_t c = 0; c < det_count; ++c) out << c << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"kind\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tri_count; ++t) out << "0\n";
  for (std::size_t l = 0; l < loop_count; ++l) out << "1\n";
  for (std::size_t c = 0; c < det_count; ++c) out << "2\n";
  out << "</DataArray>\n<DataArray type=\"Int32\" Name=\"boundary\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tri_count; ++t) out << "-1\n";
  for (std::size_t l = 0; l < loop_count; ++l) out << l << '\n';
  for (std::size_t c = 0; c < det_count; ++c) out << "-1\n";
  out << "</DataArray>\n"
      << "<DataArray type=\"Float32\" Name=\"rest_positive_fraction\" format=\"ascii\">\n";
  for (std::size_t t = 0; t < tri_count; ++t) {
    const std::uint32_t c = asset.triangle_cluster[t];
    out << (c < det_count ? number(asset.clusters[c].rest_positive_fraction) : "0") << '\n';
  }
  for (std::size_t l = 0; l < loop_count; ++l) out << "0\n";
  for (const auto& c : asset.clusters) out << number(c.rest_positive_fraction) << '\n';
  out << "</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  return out.str();
}

std::string asset_to_ply(const format::Asset& asset, const std::string& source) {
  require_rest_positions(asset, source);
  const UsedNodes used = used_nodes(asset, false);
  std::size_t edges = 0;
  for (const auto& loop : asset.boundaries) edges += loop.node_count;
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\ncomment tetseg asset surface: face colour = cluster, "
         "edges = segment boundaries\n"
      << "element vertex " << used.ids.size() << "\nproperty double x\nproperty double y\n"
      << "property double z\nelement face " << asset.triangles.size()
      << "\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
      << "property uchar blue\nproperty int cluster\nelement edge " << edges
      << "\nproperty int vertex1\nproperty int vertex2\nproperty uchar red\n"
      << "property uchar green\nproperty uchar blue\nend_header\n";
  for (std::uint32_t v : used.ids) {
    const auto& p = asset.rest_positions[v];
    out << number(p[0]) << ' ' << number(p[1]) << ' ' << number(p[2]) << '\n';
  }
  for (std::size_t t = 0; t < asset.triangles.size(); ++t) {
    const auto& tri = asset.triangles[t];
    const Rgb c = palette_color(asset.triangle_cluster[t]);
    out << "3 " << used.index[tri[0]] << ' ' << used.index[tri[1]] << ' ' << used.index[tri[2]]
        << ' ' << int(c[0]) << ' ' << int(c[1]) << ' ' << int(c[2]) << ' '
        << asset.triangle_cluster[t] << '\n';
  }
  for (const auto& loop : asset.boundaries)
    for (std::uint32_t i = 0; i < loop.node_count; ++i) {
      const std::uint32_t a = asset.boundary_nodes[loop.node_offset + i];
      const std::uint32_t b = asset.boundary_nodes[loop.node_offset + (i + 1) % loop.node_count];
      out << used.index[a] << ' ' << used.index[b] << " 0 0 0\n";
    }
  return out.str();
}

}  // namespace tetseg::tools
