// `--repair wrap`: CGAL 3D alpha wrapping of a triangle soup. Its own translation unit: the
// CGAL alpha wrapper is a slow compile.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/alpha_wrap_3.h>

#include <array>
#include <cstdint>
#include <vector>

#include "repair_internal.hpp"

namespace tetseg::preprocess::detail {

TriangleMesh alpha_wrap(const TriangleMesh& soup, double alpha, double offset) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point = Kernel::Point_3;
  using Mesh = CGAL::Surface_mesh<Point>;
  std::vector<Point> points;
  points.reserve(soup.vertices.size());
  for (const Vec3& p : soup.vertices) points.emplace_back(p[0], p[1], p[2]);
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(soup.triangles.size());
  for (const Tri& t : soup.triangles) faces.push_back({t[0], t[1], t[2]});
  Mesh wrap;
  CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
  TriangleMesh out;
  std::vector<std::uint32_t> id(wrap.number_of_vertices() + wrap.number_of_removed_vertices());
  for (const Mesh::Vertex_index v : wrap.vertices()) {
    id[v] = static_cast<std::uint32_t>(out.vertices.size());
    const Point& p = wrap.point(v);
    out.vertices.push_back({p.x(), p.y(), p.z()});
  }
  for (const Mesh::Face_index f : wrap.faces()) {
    Tri tri{};
    std::size_t k = 0;
    for (const Mesh::Vertex_index v : wrap.vertices_around_face(wrap.halfedge(f)))
      if (k < 3) tri[k++] = id[v];
    if (k == 3) out.triangles.push_back(tri);
  }
  return out;
}

}  // namespace tetseg::preprocess::detail
