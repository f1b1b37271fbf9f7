#pragma once
// Test shapes for segmentation and detector tests: closed voxel surfaces (union of unit cubes,
// refined `s` times per unit) with every grid point as a node, the inside grid points as
// interior nodes, and independent brute-force checks built on std::map adjacency.

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::test {

using preprocess::Surface;
using preprocess::Tri;
using preprocess::Vec3;

struct VoxelShape {
  std::vector<Vec3> nodes;
  Surface surface;
};

/// Voxel solid on an nx x ny x nz unit grid, `inside(x, y, z)` evaluated at each unit cell's
/// centre; each unit is refined into s^3 voxels. Node positions are in unit-grid coordinates.
inline VoxelShape make_voxel_shape(int nx, int ny, int nz, int s,
                                   const std::function<bool(double, double, double)>& inside) {
  const int gx = nx * s, gy = ny * s, gz = nz * s;
  auto filled = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= gx || j >= gy || k >= gz) return false;
    return inside((std::floor(i / double(s)) + 0.5), (std::floor(j / double(s)) + 0.5),
                  (std::floor(k / double(s)) + 0.5));
  };
  auto node = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>(i + (gx + 1) * (j + (gy + 1) * k));
  };
  VoxelShape shape;
  shape.nodes.resize(static_cast<std::size_t>(gx + 1) * (gy + 1) * (gz + 1));
  for (int k = 0; k <= gz; ++k)
    for (int j = 0; j <= gy; ++j)
      for (int i = 0; i <= gx; ++i)
        shape.nodes[node(i, j, k)] = {i / double(s), j / double(s), k / double(s)};
  auto add_quad = [&](std::array<std::uint32_t, 4> q, const Vec3& normal) {
    const Vec3& a = shape.nodes[q[0]];
    const Vec3& b = shape.nodes[q[1]];
    const Vec3& c = shape.nodes[q[2]];
    const Vec3 u{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const Vec3 v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const Vec3 n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    if (n[0] * normal[0] + n[1] * normal[1] + n[2] * normal[2] < 0) std::swap(q[1], q[3]);
    shape.surface.triangles.push_back({q[0], q[1], q[2]});
    shape.surface.triangles.push_back({q[0], q[2], q[3]});
  };
  for (int k = 0; k < gz; ++k)
    for (int j = 0; j < gy; ++j)
      for (int i = 0; i < gx; ++i) {
        if (!filled(i, j, k)) continue;
        if (!filled(i - 1, j, k))
          add_quad({node(i, j, k), node(i, j + 1, k), node(i, j + 1, k + 1), node(i, j, k + 1)},
                   {-1, 0, 0});
        if (!filled(i + 1, j, k))
          add_quad({node(i + 1, j, k), node(i + 1, j + 1, k), node(i + 1, j + 1, k + 1),
                    node(i + 1, j, k + 1)},
                   {1, 0, 0});
        if (!filled(i, j - 1, k))
          add_quad({node(i, j, k), node(i + 1, j, k), node(i + 1, j, k + 1), node(i, j, k + 1)},
                   {0, -1, 0});
        if (!filled(i, j + 1, k))
          add_quad({node(i, j + 1, k), node(i + 1, j + 1, k), node(i + 1, j + 1, k + 1),
                    node(i, j + 1, k + 1)},
                   {0, 1, 0});
        if (!filled(i, j, k - 1))
          add_quad({node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k)},
                   {0, 0, -1});
        if (!filled(i, j, k + 1))
          add_quad({node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1),
                    node(i, j + 1, k + 1)},
                   {0, 0, 1});
      }
  std::set<std::uint32_t> on_surface;
  for (const Tri& t : shape.surface.triangles) on_surface.insert(t.begin(), t.end());
  shape.surface.surface_nodes.assign(on_surface.begin(), on_surface.end());
  for (int k = 1; k < gz; ++k)
    for (int j = 1; j < gy; ++j)
      for (int i = 1; i < gx; ++i) {
        bool all = true;
        for (int d = 0; d < 8 && all; ++d)
          all = filled(i - (d & 1), j - ((d >> 1) & 1), k - ((d >> 2) & 1));
        if (all && !on_surface.count(node(i, j, k)))
          shape.surface.interior_nodes.push_back(node(i, j, k));
      }
  return shape;
}

inline Vec3 triangle_centroid(const VoxelShape& shape, std::uint32_t t) {
  const Tri& tri = shape.surface.triangles[t];
  Vec3 c{0, 0, 0};
  for (std::uint32_t v : tri)
    for (int k = 0; k < 3; ++k) c[k] += shape.nodes[v][k] / 3.0;
  return c;
}

/// Per-triangle values from a function of the triangle centroid.
inline std::vector<double> field(const VoxelShape& shape,
                                 const std::function<double(const Vec3&)>& f) {
  std::vector<double> out;
  for (std::uint32_t t = 0; t < shape.surface.triangles.size(); ++t)
    out.push_back(f(triangle_centroid(shape, t)));
  return out;
}

using Edge = std::pair<std::uint32_t, std::uint32_t>;
inline Edge edge_key(std::uint32_t a, std::uint32_t b) {
  return {std::min(a, b), std::max(a, b)};
}

/// Triangles by undirected edge, built independently of the library's half-edges.
inline std::map<Edge, std::vector<std::uint32_t>> edge_triangles(const std::vector<Tri>& tris) {
  std::map<Edge, std::vector<std::uint32_t>> out;
  for (std::uint32_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) out[edge_key(tris[t][k], tris[t][(k + 1) % 3])].push_back(t);
  return out;
}

/// Number of edge-connected components of the triangles with `keep[t]`, never crossing an
/// edge of `cut`.
inline int count_components(const std::vector<Tri>& tris, const std::vector<bool>& keep,
                            const std::set<Edge>& cut) {
  const auto by_edge = edge_triangles(tris);
  std::vector<int> label(tris.size(), -1);
  int count = 0;
  for (std::uint32_t seed = 0; seed < tris.size(); ++seed) {
    if (!keep[seed] || label[seed] >= 0) continue;
    std::vector<std::uint32_t> stack{seed};
    label[seed] = count;
    while (!stack.empty()) {
      const std::uint32_t t = stack.back();
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const Edge e = edge_key(tris[t][k], tris[t][(k + 1) % 3]);
        if (cut.count(e)) continue;
        for (std::uint32_t u : by_edge.at(e))
          if (keep[u] && label[u] < 0) {
            label[u] = count;
            stack.push_back(u);
          }
      }
    }
    ++count;
  }
  return count;
}

}  // namespace tetseg::test
