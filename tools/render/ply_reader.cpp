#include "ply_reader.hpp"

#include <algorithm>
#include <cmath>

#include "mesh_io.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {

RenderMesh read_colored_ply(const std::string& path, const std::string& scalar_property) {
  io::PlyMesh ply;
  const io::IoStatus read = io::read_ply(path, ply);
  if (!read.ok()) throw ToolError(kExitBadInput, path, read.error);
  auto fail = [&](const std::string& message) {
    throw ToolError(kExitBadInput, path, "PLY: " + message);
  };
  const io::PlyProperty* scalar = nullptr;
  if (!scalar_property.empty()) {
    scalar = ply.face_property(scalar_property);
    if (!scalar) fail("faces have no property '" + scalar_property + "'");
  }
  const io::PlyProperty* rgb[3] = {ply.face_property("red"), ply.face_property("green"),
                                   ply.face_property("blue")};

  RenderMesh mesh;
  mesh.positions = ply.vertices;
  std::vector<double> values;  // per triangle, when colouring by a scalar
  for (std::size_t f = 0; f < ply.faces.size(); ++f) {
    Rgb color{180, 180, 180};
    for (int k = 0; k < 3; ++k) {
      if (!rgb[k]) continue;
      const double v = rgb[k]->values[f];
      const double c = rgb[k]->floating ? v * 255.0 : v;
      color[static_cast<std::size_t>(k)] =
          static_cast<std::uint8_t>(std::clamp(std::lround(c), 0L, 255L));
    }
    const auto& poly = ply.faces[f];
    for (std::size_t k = 1; k + 1 < poly.size(); ++k) {  // polygons as fans
      mesh.triangles.push_back({poly[0], poly[k], poly[k + 1]});
      mesh.face_colors.push_back(color);
      values.push_back(scalar ? scalar->values[f] : 0.0);
    }
  }
  if (mesh.triangles.empty()) fail("no faces");
  if (scalar) {
    double lo = 1e300, hi = -1e300;
    for (double v : values) {
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
    for (std::size_t t = 0; t < values.size(); ++t)
      mesh.face_colors[t] = scalar_color(hi > lo ? (values[t] - lo) / (hi - lo) : 0.5);
  }
  return mesh;
}

}  // namespace tetseg::tools
