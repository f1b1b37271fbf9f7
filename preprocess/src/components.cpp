// Tet meshes with several components: splitting the surface by component and the
// per-component checks (the per-part pipeline stages are in part_stages.cpp).

#include "components.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "mesh_topology.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess::detail {
namespace {

constexpr std::uint32_t kUnset = NodeParts::kNoPart;

/// Node sets joined through every triangle (or tet) of `elements`.
template <typename Elements>
UnionFind joined_nodes(std::size_t node_count, const Elements& elements) {
  UnionFind sets(static_cast<std::uint32_t>(node_count));
  for (const auto& element : elements)
    for (std::size_t k = 1; k < element.size(); ++k) sets.unite(element[0], element[k]);
  return sets;
}

/// Each node's component from the roots of tet_node_roots, numbered in order of the first
/// surface triangle.
NodeParts node_parts(const std::vector<std::uint32_t>& roots, const Surface& surface) {
  NodeParts parts;
  std::vector<std::uint32_t> part_of_root(roots.size(), kUnset);
  for (const Tri& t : surface.triangles)
    if (part_of_root[roots[t[0]]] == kUnset) part_of_root[roots[t[0]]] = parts.count++;
  parts.part.resize(roots.size());
  for (std::uint32_t v = 0; v < parts.part.size(); ++v) parts.part[v] = part_of_root[roots[v]];
  return parts;
}

}  // namespace

std::vector<std::uint32_t> tet_node_roots(const TetMesh& mesh) {
  UnionFind sets(static_cast<std::uint32_t>(mesh.nodes.size()));
  const std::size_t tet_count = mesh.tets.size();
  for (std::size_t t = 0; t < tet_count; ++t) {
    // The parent array is prefetched a few tets ahead: node order rarely follows the tets.
    constexpr std::size_t kAhead = 8;
    if (t + kAhead < tet_count)
      for (std::uint32_t v : mesh.tets[t + kAhead]) sets.prefetch(v);
    const Tet& tet = mesh.tets[t];
    for (std::size_t k = 1; k < 4; ++k) sets.unite(tet[0], tet[k]);
  }
  std::vector<std::uint32_t> roots(mesh.nodes.size());
  for (std::uint32_t v = 0; v < roots.size(); ++v) roots[v] = sets.find(v);
  return roots;
}

std::vector<SurfacePart> split_surface(const TetMesh& mesh, const Surface& surface,
                                       const NodeParts& node_parts) {
  const std::uint32_t count = node_parts.count;
  const std::vector<std::uint32_t>& part = node_parts.part;
  if (count <= 1) {
    SurfacePart whole;
    whole.triangles.resize(surface.triangles.size());
    std::iota(whole.triangles.begin(), whole.triangles.end(), 0u);
    whole.surface = surface;
    return {whole};
  }
  std::vector<SurfacePart> parts(count);
  for (std::uint32_t t = 0; t < surface.triangles.size(); ++t) {
    SurfacePart& p = parts[part[surface.triangles[t][0]]];
    p.triangles.push_back(t);
    p.surface.triangles.push_back(surface.triangles[t]);
  }
  for (std::uint32_t t = 0; t < mesh.tets.size(); ++t)
    if (part[mesh.tets[t][0]] != kUnset) parts[part[mesh.tets[t][0]]].tets.push_back(t);
  for (std::uint32_t v : surface.surface_nodes)
    if (part[v] != kUnset) parts[part[v]].surface.surface_nodes.push_back(v);
  for (std::uint32_t v : surface.interior_nodes)
    if (part[v] != kUnset) parts[part[v]].surface.interior_nodes.push_back(v);
  return parts;
}

NodeParts check_components(const TetMesh& mesh, const Surface& surface,
                           const std::vector<std::uint32_t>& roots, const std::string& file) {
  NodeParts parts = node_parts(roots, surface);
  const std::uint32_t count = parts.count;
  const std::vector<std::uint32_t>& part = parts.part;
  // Closed surfaces per component: triangles joined through shared nodes (the surface is
  // vertex-manifold here, so this is edge-connectivity).
  UnionFind shell_sets = joined_nodes(mesh.nodes.size(), surface.triangles);
  std::vector<std::uint32_t> shells(count, 0);
  std::vector<std::uint32_t> first_node(count, kUnset);
  for (std::uint32_t v : surface.surface_nodes) {
    if (shell_sets.find(v) == v) ++shells[part[v]];
    if (first_node[part[v]] == kUnset) first_node[part[v]] = v;
  }
  for (std::uint32_t c = 0; c < count; ++c)
    if (shells[c] > 1)
      throw InputError(file, "component " + std::to_string(c + 1) + " of " + std::to_string(count) +
                                 " (node " + std::to_string(first_node[c]) + ") is bounded by " +
                                 std::to_string(shells[c]) +
                                 " closed surfaces: bodies with a cavity are not supported");
  if (count <= 1) return parts;
  std::vector<std::uint32_t> triangle_component;
  triangle_component.reserve(surface.triangles.size());
  for (const Tri& t : surface.triangles) triangle_component.push_back(part[t[0]]);
  check_not_nested(mesh.nodes, surface.triangles, triangle_component, count, file);
  return parts;
}

void check_not_nested(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                      const std::vector<std::uint32_t>& triangle_component, std::uint32_t count,
                      const std::string& file) {
  if (count <= 1) return;
  std::vector<std::array<Vec3, 2>> box(count);
  for (auto& b : box) {
    b[0] = {INFINITY, INFINITY, INFINITY};
    b[1] = {-INFINITY, -INFINITY, -INFINITY};
  }
  std::vector<std::uint32_t> first_node(count, kUnset);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const std::uint32_t c = triangle_component[t];
    if (first_node[c] == kUnset) first_node[c] = triangles[t][0];
    for (std::uint32_t v : triangles[t])
      for (int k = 0; k < 3; ++k) {
        box[c][0][k] = std::min(box[c][0][k], points[v][k]);
        box[c][1][k] = std::max(box[c][1][k], points[v][k]);
      }
  }
  for (std::uint32_t c = 0; c < count; ++c) {
    const Vec3& p = points[first_node[c]];
    for (std::uint32_t d = 0; d < count; ++d) {
      if (d == c) continue;
      bool inside_box = true;
      for (int k = 0; k < 3; ++k)
        inside_box = inside_box && p[k] >= box[d][0][k] && p[k] <= box[d][1][k];
      if (!inside_box) continue;
      double angle = 0.0;
      for (std::size_t t = 0; t < triangles.size(); ++t)
        if (triangle_component[t] == d)
          angle += solid_angle(p, points[triangles[t][0]], points[triangles[t][1]],
                               points[triangles[t][2]]);
      const double four_pi = 16.0 * std::atan(1.0);
      if (std::fabs(angle) > 0.5 * four_pi)
        throw InputError(file, "component " + std::to_string(c + 1) + " (node " +
                                   std::to_string(first_node[c]) + ") lies inside component " +
                                   std::to_string(d + 1) + " of " + std::to_string(count) +
                                   ": their volumes overlap at rest (a body inside another, or a "
                                   "cavity, is not supported)");
    }
  }
}

void check_surface_not_nested(const TriangleMesh& mesh, const std::string& file) {
  UnionFind sets = joined_nodes(mesh.vertices.size(), mesh.triangles);
  std::vector<std::uint32_t> component_of_root(mesh.vertices.size(), kUnset);
  std::vector<std::uint32_t> triangle_component;
  std::uint32_t count = 0;
  for (const Tri& t : mesh.triangles) {
    std::uint32_t& c = component_of_root[sets.find(t[0])];
    if (c == kUnset) c = count++;
    triangle_component.push_back(c);
  }
  check_not_nested(mesh.vertices, mesh.triangles, triangle_component, count, file);
}

}  // namespace tetseg::preprocess::detail
