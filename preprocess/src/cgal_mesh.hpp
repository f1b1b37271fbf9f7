#pragma once
/// \file
/// Private: the one conversion between tetseg's meshes and CGAL's points, faces and surface
/// meshes, and the kernel every CGAL unit of tetseg::preprocess uses (exact predicates,
/// inexact constructions). Include it only in .cpp files that use CGAL anyway.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail::cgal {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

inline Point to_point(const Vec3& p) {
  return Point(p[0], p[1], p[2]);
}
inline Vec3 to_vec3(const Point& p) {
  return {p.x(), p.y(), p.z()};
}

/// The points of `vertices`, in order.
inline std::vector<Point> to_points(const std::vector<Vec3>& vertices) {
  std::vector<Point> points;
  points.reserve(vertices.size());
  for (const Vec3& p : vertices) points.push_back(to_point(p));
  return points;
}

/// The triangles as CGAL polygon-soup faces (`Face`: std::array<std::size_t, 3> or
/// std::vector<std::size_t>), in order.
template <typename Face>
std::vector<Face> to_faces(const std::vector<Tri>& triangles) {
  std::vector<Face> faces;
  faces.reserve(triangles.size());
  for (const Tri& t : triangles) faces.push_back({t[0], t[1], t[2]});
  return faces;
}

/// The faces of `mesh` as triangles (the first three corners of each; faces with fewer are
/// skipped), vertices numbered in the mesh's vertex order.
inline TriangleMesh to_triangle_mesh(const SurfaceMesh& mesh) {
  TriangleMesh out;
  std::vector<std::uint32_t> id(mesh.number_of_vertices() + mesh.number_of_removed_vertices());
  for (const SurfaceMesh::Vertex_index v : mesh.vertices()) {
    id[v] = static_cast<std::uint32_t>(out.vertices.size());
    out.vertices.push_back(to_vec3(mesh.point(v)));
  }
  for (const SurfaceMesh::Face_index f : mesh.faces()) {
    Tri tri{};
    std::size_t k = 0;
    for (const SurfaceMesh::Vertex_index v : mesh.vertices_around_face(mesh.halfedge(f)))
      if (k < 3) tri[k++] = id[v];
    if (k == 3) out.triangles.push_back(tri);
  }
  return out;
}

}  // namespace tetseg::preprocess::detail::cgal
