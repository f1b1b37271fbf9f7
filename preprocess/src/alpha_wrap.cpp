// `--repair wrap`: CGAL 3D alpha wrapping of a triangle soup. Its own translation unit: the
// CGAL alpha wrapper is a slow compile.

#include <CGAL/alpha_wrap_3.h>

#include <array>
#include <vector>

#include "cgal_mesh.hpp"
#include "repair_internal.hpp"

namespace tetseg::preprocess::detail {

TriangleMesh alpha_wrap(const TriangleMesh& soup, double alpha, double offset) {
  const std::vector<cgal::Point> points = cgal::to_points(soup.vertices);
  const auto faces = cgal::to_faces<std::array<std::size_t, 3>>(soup.triangles);
  cgal::SurfaceMesh wrap;
  CGAL::alpha_wrap_3(points, faces, alpha, offset, wrap);
  return cgal::to_triangle_mesh(wrap);
}

}  // namespace tetseg::preprocess::detail
