// Approximate Hausdorff distances between two triangle surfaces (CGAL Polygon Mesh
// Processing): what a repair or a wrap cost.

#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Random.h>

#include <algorithm>
#include <array>
#include <utility>
#include <vector>

#include "cgal_mesh.hpp"
#include "repair_internal.hpp"

namespace tetseg::preprocess::detail {
namespace {

using cgal::Kernel;
using cgal::Point;
using Mesh = cgal::SurfaceMesh;

/// The soup as a polygon mesh with the same triangles: degenerate and duplicate triangles
/// dropped, orientation made consistent and non-manifold vertices duplicated (CGAL), which
/// leaves the point set covered unchanged.
Mesh as_polygon_mesh(const TriangleMesh& soup) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  std::vector<Point> points = cgal::to_points(soup.vertices);
  auto polygons = cgal::to_faces<std::vector<std::size_t>>(soup.triangles);
  pmp::repair_polygon_soup(points, polygons);
  pmp::orient_polygon_soup(points, polygons);
  Mesh mesh;
  pmp::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return mesh;
}

}  // namespace

std::pair<double, double> hausdorff_distances(const TriangleMesh& a, const TriangleMesh& b) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  const Mesh mesh_a = as_polygon_mesh(a);
  const Mesh mesh_b = as_polygon_mesh(b);
  if (mesh_a.is_empty() || mesh_b.is_empty()) return {-1.0, -1.0};
  // Vertices, edges and random points on the faces (at least kFaceSamples, or one per
  // vertex) are sampled; a fixed seed makes the figures reproducible.
  constexpr std::size_t kFaceSamples = 10000;
  auto sampling = [&](const Mesh& m) {
    return CGAL::parameters::random_seed(1).number_of_points_on_faces(
        std::max<std::size_t>(kFaceSamples, m.number_of_vertices()));
  };
  // CGAL 5.5 samples the edges with its default generator (seeded from the clock), not with
  // random_seed: reseed it before each side, or the figure (and every choice made from it:
  // auto's far-patch rule, the deviation retries) depends on the time of the run.
  auto one_side = [&](const Mesh& from, const Mesh& to) {
    CGAL::get_default_random() = CGAL::Random(1);
    return pmp::approximate_Hausdorff_distance<CGAL::Sequential_tag>(from, to, sampling(from));
  };
  const double a_to_b = one_side(mesh_a, mesh_b);
  return {a_to_b, one_side(mesh_b, mesh_a)};
}

double max_distance_to_surface(const std::vector<Vec3>& points, const TriangleMesh& surface) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  const Mesh mesh = as_polygon_mesh(surface);
  if (points.empty() || mesh.is_empty()) return -1.0;
  return pmp::max_distance_to_triangle_mesh<CGAL::Sequential_tag>(cgal::to_points(points), mesh);
}

}  // namespace tetseg::preprocess::detail
