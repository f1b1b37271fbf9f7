#include "segment_topology.hpp"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace tetseg::preprocess::detail {

std::vector<Contour> trace_contours(const HalfEdges& mesh, const std::vector<Vec3>& nodes,
                                    const std::vector<std::uint8_t>& in_set,
                                    const std::vector<std::uint32_t>& set_triangles) {
  const std::uint32_t n = mesh.size();
  auto is_border = [&](std::uint32_t h) {
    if (!in_set[h / 3]) return false;
    const std::uint32_t t = mesh.neighbor(h);
    return t == kNone || !in_set[t];
  };
  // The border half-edge that follows h: rotate around its head through the triangles
  // outside the set until the first triangle inside it.
  auto follow = [&](std::uint32_t h) -> std::uint32_t {
    std::uint32_t g = mesh.twin(h);
    for (std::uint32_t guard = 0; g != kNone && guard < n; ++guard) {
      const std::uint32_t o = mesh.twin(HalfEdges::prev(g));
      if (o == kNone) return kNone;
      if (in_set[o / 3]) return o;
      g = o;
    }
    return kNone;
  };

  std::vector<std::uint32_t> border;  // sorted: triangles ascending, then local edge
  for (std::uint32_t t : set_triangles)
    for (std::uint32_t k = 0; k < 3; ++k)
      if (is_border(3 * t + k)) border.push_back(3 * t + k);
  std::vector<std::uint8_t> visited(border.size(), 0);
  auto slot = [&](std::uint32_t h) -> std::size_t {
    const auto it = std::lower_bound(border.begin(), border.end(), h);
    return (it != border.end() && *it == h) ? static_cast<std::size_t>(it - border.begin())
                                            : border.size();
  };

  std::vector<Contour> contours;
  for (std::size_t i = 0; i < border.size(); ++i) {
    if (visited[i]) continue;
    const std::uint32_t start = border[i];
    Contour c;
    std::uint32_t h = start;
    std::size_t s = i;
    while (true) {
      visited[s] = 1;
      c.half_edges.push_back(h);
      c.length += mesh.length(nodes, h);
      const std::uint32_t nh = follow(h);
      if (nh == start) break;
      s = nh == kNone ? border.size() : slot(nh);
      if (s == border.size() || visited[s]) {
        c.closed = false;
        break;
      }
      h = nh;
    }
    contours.push_back(std::move(c));
  }
  return contours;
}

}  // namespace tetseg::preprocess::detail
