// Shape-keeping repairs of a triangle soup before meshing (`--repair fix`): degenerate and
// duplicate triangles, isolated vertices, orientation. CGAL polygon-soup processing only.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "repair_internal.hpp"

namespace tetseg::preprocess::detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Polygon = std::array<std::size_t, 3>;

}  // namespace

std::vector<RepairCount> repair_soup(TriangleMesh& mesh) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  std::vector<RepairCount> repairs;
  auto record = [&repairs](const char* kind, std::size_t count) {
    if (count > 0) repairs.push_back({kind, count});
  };
  std::vector<Point> points;
  points.reserve(mesh.vertices.size());
  for (const Vec3& p : mesh.vertices) points.emplace_back(p[0], p[1], p[2]);
  std::vector<Polygon> polygons;
  polygons.reserve(mesh.triangles.size());
  std::size_t degenerate = 0;
  for (const Tri& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++degenerate;  // a repeated corner: no area, no orientation
      continue;
    }
    polygons.push_back({t[0], t[1], t[2]});
  }
  record("triangles with a repeated corner removed", degenerate);
  // Two triangles on the same three vertices, in either orientation, are one face.
  record("duplicate triangles removed",
         pmp::merge_duplicate_polygons_in_polygon_soup(points, polygons));
  // Orientation: triangles are flipped so that neighbours agree; a vertex where the fans
  // cannot be oriented together (a non-manifold vertex) is duplicated, once per extra fan.
  const std::vector<Polygon> before = polygons;
  const std::size_t vertices_before = points.size();
  pmp::orient_polygon_soup(points, polygons);
  std::size_t flipped = 0;
  for (std::size_t i = 0; i < polygons.size() && i < before.size(); ++i)
    if (polygons[i] != before[i]) {
      // Same corners in another cyclic order is a rotation, not a flip.
      const Polygon& a = before[i];
      const Polygon& b = polygons[i];
      const bool rotation = (b[0] == a[1] && b[1] == a[2] && b[2] == a[0]) ||
                            (b[0] == a[2] && b[1] == a[0] && b[2] == a[1]);
      if (!rotation) ++flipped;
    }
  record("triangles flipped to agree with their neighbours", flipped);
  record("non-manifold vertices duplicated", points.size() - vertices_before);
  // Vertices no triangle uses any more are dropped (ids renumbered in order).
  std::vector<std::uint32_t> new_id(points.size(), UINT32_MAX);
  TriangleMesh repaired;
  for (const Polygon& polygon : polygons) {
    Tri tri;
    for (std::size_t k = 0; k < 3; ++k) {
      std::uint32_t& id = new_id[polygon[k]];
      if (id == UINT32_MAX) {
        id = static_cast<std::uint32_t>(repaired.vertices.size());
        const Point& p = points[polygon[k]];
        repaired.vertices.push_back({p.x(), p.y(), p.z()});
      }
      tri[k] = id;
    }
    repaired.triangles.push_back(tri);
  }
  // Every duplicated vertex is used, so the vertices left out were isolated ones.
  record("isolated vertices removed", points.size() - repaired.vertices.size());
  mesh = std::move(repaired);
  return repairs;
}

}  // namespace tetseg::preprocess::detail
