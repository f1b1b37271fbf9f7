// Validation of tet meshes and closed triangle surfaces. Combinatorial checks here; the
// self-intersection test is in validate_selfx.cpp (CGAL).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "components.hpp"
#include "mesh_topology.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "validate_internal.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess {
namespace {

using detail::UnionFind;

constexpr double kDegenerateArea = 1e-12;  // |2 area| relative to max edge^2

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

/// The checks shared by tet-mesh boundaries and triangle surfaces: closed, edge-manifold,
/// consistently oriented, vertex-manifold, one component (unless allowed), no
/// self-intersection.
void check_surface(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                   const std::string& file, const detail::SurfaceCheck& options,
                   TriangleMesh* split) {
  if (triangles.empty()) throw InputError(file, "surface has no triangles");
  // Half-edges grouped by undirected edge.
  struct HalfEdge {
    std::uint32_t lo, hi, tri;
    bool forward;  // lo -> hi in the triangle's winding
  };
  std::vector<HalfEdge> half;
  half.reserve(triangles.size() * 3);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = triangles[t][k];
      const std::uint32_t b = triangles[t][(k + 1) % 3];
      half.push_back({std::min(a, b), std::max(a, b), t, a < b});
    }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return std::tie(x.lo, x.hi, x.tri) < std::tie(y.lo, y.hi, y.tri);
  });
  std::size_t border = 0;
  std::size_t non_manifold = 0;
  std::size_t misoriented = 0;
  std::size_t first_border = SIZE_MAX;
  std::size_t first_non_manifold = SIZE_MAX;
  std::size_t first_misoriented = SIZE_MAX;
  std::vector<std::pair<std::size_t, std::size_t>> pairs;  // manifold edges: half-edge indices
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i + 1;
    while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi) ++j;
    if (j - i == 1) {
      if (border++ == 0) first_border = i;
    } else if (j - i > 2) {
      if (non_manifold++ == 0) first_non_manifold = i;
    } else if (half[i].forward == half[i + 1].forward) {
      if (misoriented++ == 0) first_misoriented = i;
    } else {
      pairs.emplace_back(i, i + 1);
    }
    i = j;
  }
  auto edge_name = [&](std::size_t i) {
    return "vertices " + std::to_string(half[i].lo) + " and " + std::to_string(half[i].hi);
  };
  if (non_manifold > 0)
    throw InputError(file, "surface has " +
                               plural(non_manifold, "non-manifold edge", "non-manifold edges") +
                               " (shared by more than two triangles), first between " +
                               edge_name(first_non_manifold));
  if (border > 0)
    throw InputError(file, "surface is not closed (" +
                               plural(border, "border edge", "border edges") + ", first between " +
                               edge_name(first_border) + ")");
  if (misoriented > 0)
    throw InputError(file, "surface is not consistently oriented (" +
                               plural(misoriented, "edge", "edges") +
                               " with both triangles in the same direction, first between " +
                               edge_name(first_misoriented) + ")");
  // Vertex manifoldness: the triangles around a vertex must form one fan. Corners (t, k) are
  // joined across every manifold edge at both of its end vertices.
  UnionFind corners(static_cast<std::uint32_t>(triangles.size() * 3));
  auto corner_of = [&](std::uint32_t t, std::uint32_t v) {
    for (std::uint32_t k = 0; k < 3; ++k)
      if (triangles[t][k] == v) return t * 3 + k;
    return t * 3;
  };
  UnionFind components(static_cast<std::uint32_t>(triangles.size()));
  for (const auto& [a, b] : pairs) {
    const std::uint32_t ta = half[a].tri;
    const std::uint32_t tb = half[b].tri;
    corners.unite(corner_of(ta, half[a].lo), corner_of(tb, half[a].lo));
    corners.unite(corner_of(ta, half[a].hi), corner_of(tb, half[a].hi));
    components.unite(ta, tb);
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> vertex_fan;  // (vertex, fan root)
  vertex_fan.reserve(triangles.size() * 3);
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    for (std::uint32_t k = 0; k < 3; ++k)
      vertex_fan.emplace_back(triangles[t][k], corners.find(t * 3 + k));
  std::sort(vertex_fan.begin(), vertex_fan.end());
  vertex_fan.erase(std::unique(vertex_fan.begin(), vertex_fan.end()), vertex_fan.end());
  std::size_t bad_vertices = 0;
  std::uint32_t first_bad_vertex = 0;
  for (std::size_t i = 1; i < vertex_fan.size(); ++i)
    if (vertex_fan[i].first == vertex_fan[i - 1].first &&
        (i < 2 || vertex_fan[i - 2].first != vertex_fan[i].first)) {
      if (bad_vertices++ == 0) first_bad_vertex = vertex_fan[i].first;
    }
  if (bad_vertices > 0 && !options.allow_pinched_vertices)
    throw InputError(file,
                     "surface has " +
                         plural(bad_vertices, "non-manifold vertex", "non-manifold vertices") +
                         " (several fans of triangles meet there), first is vertex " +
                         std::to_string(first_bad_vertex));
  std::size_t count = 0;
  for (std::uint32_t t = 0; t < triangles.size(); ++t)
    if (components.find(t) == t) ++count;
  if (count > 1 && !options.allow_components)
    throw InputError(file,
                     "surface has " + std::to_string(count) + " connected components (expected 1)");
  // Pinched vertices: one copy per extra fan, so the surface becomes a manifold mesh.
  std::vector<Vec3> split_points;
  std::vector<Tri> split_triangles;
  std::vector<char> pinched;
  if (bad_vertices > 0) {
    split_points = points;
    split_triangles = triangles;
    pinched.assign(points.size(), 0);
    std::vector<std::uint32_t> copy_of(vertex_fan.size());
    for (std::size_t i = 0; i < vertex_fan.size(); ++i) {
      if (i > 0 && vertex_fan[i].first == vertex_fan[i - 1].first) {
        pinched[vertex_fan[i].first] = 1;
        copy_of[i] = static_cast<std::uint32_t>(split_points.size());
        split_points.push_back(points[vertex_fan[i].first]);
      } else {
        copy_of[i] = vertex_fan[i].first;
      }
    }
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
      for (std::uint32_t k = 0; k < 3; ++k) {
        const std::pair<std::uint32_t, std::uint32_t> key(triangles[t][k], corners.find(t * 3 + k));
        const auto it = std::lower_bound(vertex_fan.begin(), vertex_fan.end(), key);
        split_triangles[t][k] = copy_of[static_cast<std::size_t>(it - vertex_fan.begin())];
      }
  }
  const std::vector<Vec3>& check_points = bad_vertices > 0 ? split_points : points;
  const std::vector<Tri>& check_triangles = bad_vertices > 0 ? split_triangles : triangles;
  std::vector<std::pair<std::size_t, std::size_t>> crossings =
      detail::self_intersecting_pairs(check_points, check_triangles);
  if (bad_vertices > 0) {
    // Pairs that share a pinched vertex touch there by construction.
    auto shares_pinch = [&](const std::pair<std::size_t, std::size_t>& p) {
      for (std::uint32_t u : triangles[p.first])
        for (std::uint32_t v : triangles[p.second])
          if (u == v && pinched[u]) return true;
      return false;
    };
    crossings.erase(std::remove_if(crossings.begin(), crossings.end(), shares_pinch),
                    crossings.end());
  }
  if (!crossings.empty()) {
    auto tri_name = [&](std::size_t t) {
      return std::to_string(t) + " (" + std::to_string(triangles[t][0]) + " " +
             std::to_string(triangles[t][1]) + " " + std::to_string(triangles[t][2]) + ")";
    };
    throw InputError(file, "surface self-intersects (" +
                               plural(crossings.size(), "pair of triangles", "pairs of triangles") +
                               ", first triangles " + tri_name(crossings.front().first) + " and " +
                               tri_name(crossings.front().second) + ")");
  }
  if (split != nullptr && bad_vertices > 0) {
    split->vertices = std::move(split_points);
    split->triangles = std::move(split_triangles);
  }
}

/// Throws InputError when a boundary triangle is too thin for the charge solver
/// (detail::is_degenerate_panel: the test charge applies, so that a mesh this validation
/// accepts never fails later in charge).
void check_boundary_panels(const std::vector<Vec3>& points, const std::vector<Tri>& triangles,
                           const std::string& file) {
  std::vector<double> area(triangles.size()), longest(triangles.size());
  double surface_longest = 0.0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Vec3& a = points[triangles[t][0]];
    const Vec3& b = points[triangles[t][1]];
    const Vec3& c = points[triangles[t][2]];
    area[t] = 0.5 * detail::norm(detail::cross(detail::sub(b, a), detail::sub(c, a)));
    longest[t] = std::max({detail::distance_between(a, b), detail::distance_between(b, c),
                           detail::distance_between(c, a)});
    surface_longest = std::max(surface_longest, longest[t]);
  }
  std::size_t degenerate = 0;
  std::size_t first = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    if (detail::is_degenerate_panel(area[t], longest[t], surface_longest) && degenerate++ == 0)
      first = t;
  if (degenerate > 0) {
    std::ostringstream msg;
    msg << "boundary has "
        << plural(degenerate, "near-zero-area triangle", "near-zero-area triangles")
        << " (area at most 1e-12 of the longest boundary edge squared, or 1e-10 of its own), "
           "first is triangle "
        << first << " (nodes " << triangles[first][0] << " " << triangles[first][1] << " "
        << triangles[first][2] << ", area " << area[first] << ", longest edge " << longest[first]
        << ")";
    throw InputError(file, msg.str());
  }
}

}  // namespace

void validate_tet_mesh(const TetMesh& mesh, const Surface& surface, const std::string& file) {
  detail::validate_tet_mesh(mesh, surface, detail::match_faces(mesh, true), file);
}

detail::NodeParts detail::validate_tet_mesh(const TetMesh& mesh, const Surface& surface,
                                            const FaceMatch& match, const std::string& file) {
  if (!match.tets_checked) throw std::logic_error("validate_tet_mesh: faces matched unchecked");
  const std::size_t n = mesh.nodes.size();
  if (mesh.tets.empty()) throw InputError(file, "mesh has no tetrahedra");
  detail::check_finite(mesh.nodes, file, "node");
  // The per-tet checks were made while matching the faces (match_faces).
  const TetChecks& checks = match.tets;
  if (checks.first_out_of_range != SIZE_MAX)
    for (std::uint32_t v : mesh.tets[checks.first_out_of_range])
      if (v >= n)
        throw InputError(file, "tet " + std::to_string(checks.first_out_of_range) +
                                   " refers to node " + std::to_string(v) + " out of range (" +
                                   std::to_string(n) + " nodes)");
  if (checks.unused > 0)
    throw InputError(file, plural(checks.unused, "node is", "nodes are") +
                               " used by no tet, first is node " +
                               std::to_string(checks.first_unused));
  if (checks.degenerate > 0)
    throw InputError(file, plural(checks.degenerate, "degenerate tet", "degenerate tets") +
                               " (zero volume), first is tet " +
                               std::to_string(checks.first_degenerate));
  if (checks.inverted > 0)
    throw InputError(file, plural(checks.inverted, "inverted tet", "inverted tets") +
                               " (negative volume), first is tet " +
                               std::to_string(checks.first_inverted));
  // Faces shared by more than two tets.
  const std::size_t crowded = match.crowded;
  const std::array<std::uint32_t, 3>& first_crowded = match.first_crowded;
  if (crowded > 0)
    throw InputError(file, plural(crowded, "face is", "faces are") +
                               " shared by more than two tets (non-manifold), first has nodes " +
                               std::to_string(first_crowded[0]) + " " +
                               std::to_string(first_crowded[1]) + " " +
                               std::to_string(first_crowded[2]));
  for (const Tri& t : surface.triangles)
    for (std::uint32_t v : t)
      if (v >= n)
        throw InputError(file, "surface refers to node " + std::to_string(v) + " out of range");
  detail::SurfaceCheck options;
  options.allow_components = true;
  check_surface(mesh.nodes, surface.triangles, file, options, nullptr);
  check_boundary_panels(mesh.nodes, surface.triangles, file);
  return detail::check_components(mesh, surface, match.node_roots, file);
}

void validate_closed_surface(const TriangleMesh& mesh, const std::string& file,
                             bool allow_components) {
  detail::SurfaceCheck check;
  check.allow_components = allow_components;
  detail::validate_closed_surface(mesh, file, check, nullptr);
}

void detail::check_finite(const std::vector<Vec3>& points, const std::string& file,
                          const char* noun) {
  for (std::size_t i = 0; i < points.size(); ++i)
    for (double c : points[i])
      if (!std::isfinite(c))
        throw InputError(file, std::string(noun) + " " + std::to_string(i) +
                                   " has a non-finite coordinate (" + std::to_string(c) + ")");
}

void detail::check_triangle_indices(const TriangleMesh& mesh, const std::string& file) {
  const std::size_t n = mesh.vertices.size();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::uint32_t v : mesh.triangles[t])
      if (v >= n)
        throw InputError(file, "triangle " + std::to_string(t) + " refers to vertex " +
                                   std::to_string(v) + " out of range (" + std::to_string(n) +
                                   " vertices)");
}

void detail::validate_closed_surface(const TriangleMesh& mesh, const std::string& file,
                                     const SurfaceCheck& options, TriangleMesh* split) {
  detail::check_finite(mesh.vertices, file, "vertex");
  check_triangle_indices(mesh, file);
  std::size_t zero_area = 0;
  std::size_t first_zero = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Tri& tri = mesh.triangles[t];
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3& b = mesh.vertices[tri[1]];
    const Vec3& c = mesh.vertices[tri[2]];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double x = u[1] * v[2] - u[2] * v[1];
    const double y = u[2] * v[0] - u[0] * v[2];
    const double z = u[0] * v[1] - u[1] * v[0];
    const double edge = std::max({detail::distance_between(a, b), detail::distance_between(a, c),
                                  detail::distance_between(b, c)});
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2] ||
        !(std::sqrt(x * x + y * y + z * z) > kDegenerateArea * edge * edge)) {
      if (zero_area++ == 0) first_zero = t;
    }
  }
  if (zero_area > 0)
    throw InputError(file, plural(zero_area, "zero-area triangle", "zero-area triangles") +
                               ", first is triangle " + std::to_string(first_zero));
  check_surface(mesh.vertices, mesh.triangles, file, options, split);
}

}  // namespace tetseg::preprocess
