// tetseg-dump: inspects an asset. Links the runtime only.

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <CLI/CLI.hpp>

#include "mesh_output.hpp"
#include "tetseg/format/asset_json.hpp"
#include "tetseg/format/source_vertices.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tool_support.hpp"

namespace {

using tetseg::format::Asset;

/// Per cluster: edges of its triangles whose other triangle lies in another cluster.
std::vector<std::uint32_t> boundary_edges_per_cluster(const Asset& asset) {
  std::unordered_map<std::uint64_t, std::uint32_t> first_triangle;
  std::vector<std::uint32_t> counts(asset.clusters.size(), 0);
  first_triangle.reserve(asset.triangles.size() * 3);
  for (std::uint32_t t = 0; t < asset.triangles.size(); ++t) {
    const auto& tri = asset.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = std::min(tri[k], tri[(k + 1) % 3]);
      const std::uint32_t b = std::max(tri[k], tri[(k + 1) % 3]);
      const std::uint64_t key = (std::uint64_t{a} << 32) | b;
      const auto [it, inserted] = first_triangle.emplace(key, t);
      if (inserted) continue;
      const std::uint32_t ca = asset.triangle_cluster[it->second];
      const std::uint32_t cb = asset.triangle_cluster[t];
      if (ca != cb) {
        ++counts[ca];
        ++counts[cb];
      }
    }
  }
  return counts;
}

/// Connected components of the surface (triangles joined through shared nodes): the bodies
/// of an asset built from a tet mesh with several components.
std::size_t surface_components(const Asset& asset) {
  std::vector<std::uint32_t> parent(asset.node_count);
  for (std::uint32_t v = 0; v < asset.node_count; ++v) parent[v] = v;
  auto find = [&](std::uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  std::size_t count = 0;
  std::vector<char> used(asset.node_count, 0);
  for (const auto& tri : asset.triangles)
    for (std::uint32_t v : tri) {
      count += used[v] ? 0 : 1;
      used[v] = 1;
    }
  for (const auto& tri : asset.triangles)
    for (int k = 1; k < 3; ++k) {
      const std::uint32_t a = find(tri[0]);
      const std::uint32_t b = find(tri[k]);
      if (a != b) {
        parent[std::max(a, b)] = std::min(a, b);
        --count;
      }
    }
  return count;
}

/// "major.minor" as the file's envelope declares it (the file has loaded, so it is valid).
std::string version_string(const std::vector<std::uint8_t>& bytes) {
  std::uint16_t major = 0;
  std::uint16_t minor = 0;
  tetseg::format::peek_version(bytes.data(), bytes.size(), major, minor);
  return std::to_string(major) + "." + std::to_string(minor);
}

std::vector<std::uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw tetseg::tools::ToolError(tetseg::tools::kExitBadInput, path, "cannot open file");
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
  if (in.bad()) throw tetseg::tools::ToolError(tetseg::tools::kExitBadInput, path, "read error");
  return bytes;
}

void print_summary(const std::string& path, const std::string& version, const Asset& asset) {
  const auto edges = boundary_edges_per_cluster(asset);
  std::printf("%s: tetseg asset, format %s\n", path.c_str(), version.c_str());
  std::printf("  nodes               %u%s\n", asset.node_count,
              asset.rest_positions.empty() ? " (no rest positions)" : "");
  std::printf("  surface triangles   %zu\n", asset.triangles.size());
  std::printf("  components          %zu\n", surface_components(asset));
  std::printf("  body                %s\n", tetseg::format::body_kind_name(asset.body_kind));
  std::printf("  detector form       %s\n",
              tetseg::format::detector_form_name(asset.detector_form));
  std::printf("  clusters            %zu\n", asset.clusters.size());
  std::printf("  segment boundaries  %zu (%zu boundary nodes)\n", asset.boundaries.size(),
              asset.boundary_nodes.size());
  std::printf("  bvh nodes           %zu\n", asset.bvh_nodes.size());
  std::printf("  provenance          %s, source %s\n", asset.provenance.tool_version.c_str(),
              asset.provenance.source.c_str());
  for (const auto& [key, value] : asset.provenance.options) {
    std::printf("    %-36s %s\n", key.c_str(), value.c_str());
  }
  // How far the asset's surface is from the input's (recorded by tetseg build since 0.2).
  const auto recorded = [&](const char* key) -> std::string {
    for (const auto& [k, v] : asset.provenance.options)
      if (k == key) return v;
    return "";
  };
  if (!recorded("deviation.input_to_asset").empty())
    std::printf(
        "  deviation           %s / %s of the input's diagonal, %s / %s absolute "
        "(input to asset / asset to input)\n",
        recorded("deviation.input_to_asset").c_str(), recorded("deviation.asset_to_input").c_str(),
        recorded("deviation.input_to_asset_absolute").c_str(),
        recorded("deviation.asset_to_input_absolute").c_str());
  if (!recorded("deviation.excess").empty())
    std::printf(
        "  deviation excess    %s of the diagonal over --max-deviation, after %s meshing "
        "retries\n",
        recorded("deviation.excess").c_str(), recorded("deviation.meshing_retries").c_str());
  std::size_t flagged = 0;
  for (const auto& cluster : asset.clusters)
    flagged += (cluster.flags & tetseg::format::kClusterOverlapOnly) ? 1 : 0;
  std::printf("  overlap-only        %zu clusters (culled by BVH overlap only)\n", flagged);
  if (asset.detector_form != tetseg::format::DetectorForm::kTetPoint && !asset.clusters.empty()) {
    std::uint32_t least = UINT32_MAX, most = 0;
    for (const auto& cluster : asset.clusters) {
      least = std::min(least, cluster.detector_term_count);
      most = std::max(most, cluster.detector_term_count);
    }
    std::printf("  detector terms      %zu (%u to %u per cluster, mean %.2f)\n",
                asset.detector_terms.size(), least, most,
                double(asset.detector_terms.size()) / double(asset.clusters.size()));
  }
  if (asset.detector_form == tetseg::format::DetectorForm::kBones) {
    // Escaped (names come from the input's skin), the first 64 (--json lists all).
    std::printf("  bones               %zu:", asset.bone_names.size());
    for (std::size_t b = 0; b < asset.bone_names.size() && b < 64; ++b)
      std::printf(" %zu=\"%s\"", b, tetseg::format::json_escape(asset.bone_names[b]).c_str());
    std::printf("%s\n", asset.bone_names.size() > 64 ? " ..." : "");
  }
  if (asset.body_kind == tetseg::format::BodyKind::kSurface) {
    if (asset.source_vertex_nodes.empty())
      std::printf("  source vertices     none mapped (node i is vertex i of the input file)\n");
    else
      std::printf(
          "  source vertices     %zu mapped onto %u nodes (frames in the file's vertex "
          "order: gather_node_positions)\n",
          asset.source_vertex_nodes.size(), asset.node_count);
  }
  std::printf("  %-8s %10s %14s %15s %-12s  %s\n", "cluster", "triangles", "rest_positive",
              "boundary_edges", "culling", "detector");
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    const auto& cluster = asset.clusters[c];
    const bool overlap_only = (cluster.flags & tetseg::format::kClusterOverlapOnly) != 0;
    std::printf("  %-8zu %10u %14.4f %15u %-12s  %s", c, cluster.triangle_count,
                cluster.rest_positive_fraction, edges[c], overlap_only ? "overlap-only" : "rvbc",
                tetseg::tools::detector_text(asset, cluster).c_str());
    if (!asset.rest_positions.empty() ||
        asset.detector_form != tetseg::format::DetectorForm::kTetPoint) {
      const auto p = tetseg::format::rest_detector_position(asset, cluster);
      std::printf(" at (%.6g, %.6g, %.6g)", p[0], p[1], p[2]);
    }
    std::printf("\n");
  }
}

void print_json(const std::string& version, const Asset& asset) {
  using tetseg::format::json_escape;
  const auto edges = boundary_edges_per_cluster(asset);
  std::ostringstream out;
  out.precision(9);
  out << "{\n  \"format_version\": \"" << version << "\",\n";
  out << "  \"body\": \"" << tetseg::format::body_kind_name(asset.body_kind) << "\",\n";
  out << "  \"detector_form\": \"" << tetseg::format::detector_form_name(asset.detector_form)
      << "\",\n";
  out << "  \"bone_names\": [";
  for (std::size_t b = 0; b < asset.bone_names.size(); ++b)
    out << (b ? ", \"" : "\"") << json_escape(asset.bone_names[b]) << '"';
  out << "],\n";
  out << "  \"nodes\": " << asset.node_count << ",\n";
  out << "  \"source_vertices\": " << tetseg::format::source_vertex_count(asset)
      << ", \"source_vertex_map\": " << (asset.source_vertex_nodes.empty() ? "false" : "true")
      << ",\n";
  out << "  \"rest_positions\": " << (asset.rest_positions.empty() ? "false" : "true") << ",\n";
  out << "  \"surface_triangles\": " << asset.triangles.size() << ",\n";
  out << "  \"components\": " << surface_components(asset) << ",\n";
  out << "  \"bvh_nodes\": " << asset.bvh_nodes.size() << ",\n";
  out << "  \"clusters\": [";
  for (std::size_t c = 0; c < asset.clusters.size(); ++c) {
    const auto& cluster = asset.clusters[c];
    out << (c ? ",\n    " : "\n    ") << "{\"triangles\": " << cluster.triangle_count << ", "
        << tetseg::format::detector_json(asset, cluster)
        << ", \"rest_positive_fraction\": " << cluster.rest_positive_fraction
        << ", \"boundary_edges\": " << edges[c] << ", \"bvh_nodes\": " << cluster.bvh_count << "}";
  }
  out << "\n  ],\n  \"segment_boundaries\": [";
  for (std::size_t b = 0; b < asset.boundaries.size(); ++b) {
    const auto& loop = asset.boundaries[b];
    out << (b ? ", " : "") << "{\"nodes\": [";
    for (std::uint32_t i = 0; i < loop.node_count; ++i) {
      out << (i ? ", " : "") << asset.boundary_nodes[loop.node_offset + i];
    }
    out << "]}";
  }
  out << "],\n  \"provenance\": {\"tool_version\": \"" << json_escape(asset.provenance.tool_version)
      << "\", \"source\": \"" << json_escape(asset.provenance.source)
      << "\", \"options\": " << tetseg::format::provenance_options_json(asset) << "}\n}\n";
  std::cout << out.str();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tetseg::tools;
  CLI::App app{"tetseg-dump " TETSEG_VERSION ": inspect a tetseg asset", "tetseg-dump"};
  app.set_version_flag("--version", "tetseg-dump " TETSEG_VERSION);
  std::string path;
  bool json = false;
  app.add_option("asset", path, "Asset file written by `tetseg build`")->required();
  app.add_flag("--json", json, "Print JSON instead of the human summary");
  std::string vtu_path, ply_path;
  app.add_option("--vtu", vtu_path,
                 "Also write the surface with cluster ids, boundaries and "
                 "detector points as ParaView .vtu (needs rest positions)");
  app.add_option("--ply", ply_path,
                 "Also write the surface with cluster colours and boundary "
                 "edges as .ply (needs rest positions)");
  auto dump = [&] {
    tetseg::Asset asset;
    std::string detail;
    const std::vector<std::uint8_t> bytes = read_bytes(path);
    const tetseg::Status status = tetseg::load_asset(bytes.data(), bytes.size(), asset, &detail);
    if (status != tetseg::Status::kOk) {
      print_error("tetseg-dump", path,
                  std::string(tetseg::to_string(status)) + (detail.empty() ? "" : ": " + detail));
      return kExitBadInput;
    }
    if (!vtu_path.empty()) write_file_atomic(vtu_path, asset_to_vtu(asset.data(), path));
    if (!ply_path.empty()) write_file_atomic(ply_path, asset_to_ply(asset.data(), path));
    const std::string version = version_string(bytes);
    if (json) {
      print_json(version, asset.data());
    } else {
      print_summary(path, version, asset.data());
    }
    return kExitOk;
  };
  return run_tool("tetseg-dump", app, argc, argv, dump, path);
}
