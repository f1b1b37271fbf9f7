// CGAL Mesh_3 on a closed triangle surface (Polyhedral_mesh_domain_3 on a Surface_mesh, or
// Polyhedral_mesh_domain_with_features_3 when sharp edges are protected). Slow to compile;
// keep changes rare.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polyhedral_mesh_domain_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Surface_mesh.h>

#include <array>
#include <stdexcept>
#include <vector>

#include "mesh3_extract.hpp"

namespace tetseg::preprocess::detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Domain = CGAL::Polyhedral_mesh_domain_3<SurfaceMesh, Kernel>;
using FeaturesDomain = CGAL::Polyhedral_mesh_domain_with_features_3<Kernel, SurfaceMesh>;

}  // namespace

TetMesh mesh_polyhedral_surface(const TriangleMesh& surface, const Mesh3Criteria& criteria) {
  std::vector<Point> points;
  points.reserve(surface.vertices.size());
  for (const Vec3& p : surface.vertices) points.emplace_back(p[0], p[1], p[2]);
  std::vector<std::array<std::size_t, 3>> faces;
  faces.reserve(surface.triangles.size());
  for (const Tri& t : surface.triangles) faces.push_back({t[0], t[1], t[2]});
  SurfaceMesh mesh;
  CGAL::Polygon_mesh_processing::polygon_soup_to_polygon_mesh(points, faces, mesh);
  if (mesh.number_of_faces() != surface.triangles.size())
    throw std::runtime_error("surface could not be converted to a polygon mesh");
  CGAL::Random rng(0);
  if (criteria.sharp_edge_angle > 0) {
    FeaturesDomain domain(mesh, &rng);
    domain.detect_features(criteria.sharp_edge_angle);
    return mesh_domain(domain, criteria);
  }
  const Domain domain(mesh, &rng);
  return mesh_domain(domain, criteria);
}

}  // namespace tetseg::preprocess::detail
