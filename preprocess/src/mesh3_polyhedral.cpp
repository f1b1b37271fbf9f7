// CGAL Mesh_3 on a closed triangle surface (Polyhedral_mesh_domain_3 on a Surface_mesh, or
// Polyhedral_mesh_domain_with_features_3 when sharp edges are protected). Slow to compile;
// keep changes rare.

#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polyhedral_mesh_domain_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>

#include <array>
#include <stdexcept>
#include <vector>

#include "cgal_mesh.hpp"
#include "mesh3_extract.hpp"

namespace tetseg::preprocess::detail {
namespace {

using cgal::Kernel;
using cgal::SurfaceMesh;
using Domain = CGAL::Polyhedral_mesh_domain_3<SurfaceMesh, Kernel>;
using FeaturesDomain = CGAL::Polyhedral_mesh_domain_with_features_3<Kernel, SurfaceMesh>;

}  // namespace

TetMesh mesh_polyhedral_surface(const TriangleMesh& surface, const Mesh3Criteria& criteria) {
  const std::vector<cgal::Point> points = cgal::to_points(surface.vertices);
  const auto faces = cgal::to_faces<std::array<std::size_t, 3>>(surface.triangles);
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
