#pragma once
/// \file
/// A small software rasteriser for pictures of meshes (clusters, charge): orthographic view,
/// z-buffer, flat Lambert shading, optional poly-lines drawn on top, 2x2 supersampling; and
/// PNG encoding through libpng. Deterministic: the same mesh and options give the same bytes.
/// Single-threaded; no global state.

#include <array>
#include <cstdint>
#include <vector>

#include "mesh_output.hpp"

namespace tetseg::tools {

/// What to draw. Triangles are wound outward (back faces are culled, so closed surfaces only
/// show their outside); `face_colors` has one colour per triangle.
struct RenderMesh {
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Rgb> face_colors;
  /// Closed poly-lines (indices into positions) drawn over visible surfaces.
  std::vector<std::vector<std::uint32_t>> loops;
  Rgb loop_color{20, 20, 20};
  /// Points drawn as small squares over visible surfaces (e.g. detector nodes: they are
  /// inside the solid, so they are drawn without depth test when `points_on_top`).
  std::vector<std::uint32_t> points;
  Rgb point_color{0, 0, 0};
  bool points_on_top = false;
};

struct RenderOptions {
  int width = 800;   ///< pixels, 16..8192
  int height = 600;  ///< pixels, 16..8192
  /// Direction the camera looks along (from the eye to the object); need not be unit length.
  std::array<double, 3> view = {-1.0, -0.6, -0.8};
  std::array<double, 3> up = {0.0, 0.0, 1.0};  ///< screen up (projected; any non-parallel)
  Rgb background{255, 255, 255};
  double line_width = 2.0;  ///< pixels of the final image
};

/// Renders to `width * height * 3` bytes (RGB, rows top to bottom). Indices out of range are
/// skipped. Throws ToolError(kExitUsage) for sizes outside 16..8192 or a zero view vector.
std::vector<std::uint8_t> render_rgb(const RenderMesh& mesh, const RenderOptions& options);

/// PNG (8-bit RGB, no interlace) of `rgb` (width * height * 3 bytes, rows top to bottom),
/// encoded by libpng: `compress` gives zlib level 9 with libpng's adaptive filters; otherwise
/// unfiltered rows in zlib stored blocks. Deterministic for a given libpng and zlib.
std::vector<std::uint8_t> encode_png(const std::vector<std::uint8_t>& rgb, int width, int height,
                                     bool compress = true);

}  // namespace tetseg::tools
