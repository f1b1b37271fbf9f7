// tetseg-render: a PNG picture of an asset's clusters (segment boundaries drawn, detector nodes
// optional), or of a PLY surface with face colours / a face scalar such as the charge written
// by `tetseg charge -o x.ply`. Links the runtime only.

#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "mesh_output.hpp"
#include "ply_reader.hpp"
#include "render.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tool_support.hpp"

namespace {

using namespace tetseg::tools;

RenderMesh mesh_from_asset(const std::string& path, bool boundaries, bool detectors) {
  tetseg::Asset loaded;
  std::string detail;
  const tetseg::Status status = tetseg::load_asset_file(path, loaded, &detail);
  if (status != tetseg::Status::kOk)
    throw ToolError(kExitBadInput, path,
                    std::string(tetseg::to_string(status)) + (detail.empty() ? "" : ": " + detail));
  const tetseg::format::Asset& asset = loaded.data();
  require_rest_positions(asset, path);
  RenderMesh mesh;
  mesh.positions = asset.rest_positions;
  mesh.triangles = asset.triangles;
  // Overlap-only clusters (no detector sees them well) are drawn half grey.
  for (std::uint32_t c : asset.triangle_cluster) {
    Rgb color = palette_color(c);
    if (asset.clusters[c].flags & tetseg::format::kClusterOverlapOnly)
      for (auto& channel : color) channel = static_cast<std::uint8_t>((channel + 160) / 2);
    mesh.face_colors.push_back(color);
  }
  if (boundaries)
    for (const auto& loop : asset.boundaries)
      mesh.loops.emplace_back(asset.boundary_nodes.begin() + loop.node_offset,
                              asset.boundary_nodes.begin() + loop.node_offset + loop.node_count);
  if (detectors) {
    // Detector points (inside tets or at nodes) are appended as extra positions.
    for (const auto& c : asset.clusters) {
      mesh.points.push_back(static_cast<std::uint32_t>(mesh.positions.size()));
      mesh.positions.push_back(tetseg::format::rest_detector_position(asset, c));
    }
    mesh.points_on_top = true;
  }
  return mesh;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-render " TETSEG_VERSION
               ": PNG picture of an asset's clusters or of a coloured PLY surface",
               "tetseg-render"};
  app.set_version_flag("--version", "tetseg-render " TETSEG_VERSION);
  std::string input, output, scalar;
  std::array<double, 3> view{-1.0, -0.6, -0.8}, up{0.0, 0.0, 1.0};
  int width = 800, height = 600;
  bool no_boundaries = false, detectors = false, stored = false;
  app.add_option("input", input,
                 "Asset from `tetseg build`, or a .ply with face colours (e.g. `tetseg charge -o`)")
      ->required();
  app.add_option("-o,--output", output, "PNG file to write")->required();
  app.add_option("--view", view, "Direction the camera looks along, x y z")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--up", up, "Screen-up direction, x y z")->delimiter(',')->capture_default_str();
  app.add_option("--width", width, "Image width in pixels")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  app.add_option("--height", height, "Image height in pixels")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  app.add_flag("--no-boundaries", no_boundaries, "Asset: do not draw segment boundaries");
  app.add_flag(
      "--detectors", detectors,
      "Asset: draw detector points (black squares, on top; overlap-only clusters are drawn "
      "half grey)");
  app.add_flag("--png-stored", stored, "Write the PNG uncompressed (zlib stored blocks)");
  app.add_option("--scalar", scalar,
                 "PLY: colour faces by this face property (rescaled to [min,max]) instead of "
                 "their colours, e.g. --scalar charge");
  auto render = [&] {
    const bool ply = extension_of(input) == ".ply";
    if (!ply && !scalar.empty())
      throw ToolError(kExitUsage, "", "--scalar applies to .ply input only");
    const RenderMesh mesh =
        ply ? read_colored_ply(input, scalar) : mesh_from_asset(input, !no_boundaries, detectors);
    RenderOptions options;
    options.width = width;
    options.height = height;
    options.view = view;
    options.up = up;
    if (std::abs(view[0]) + std::abs(view[1]) + std::abs(view[2]) == 0.0)
      throw ToolError(kExitUsage, "", "--view must not be zero");
    const std::vector<std::uint8_t> rgb = render_rgb(mesh, options);
    write_file_atomic(output, encode_png(rgb, width, height, !stored));
    return kExitOk;
  };
  return run_tool("tetseg-render", app, argc, argv, render, input);
}
