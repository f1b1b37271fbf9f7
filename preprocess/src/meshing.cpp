// Meshing options, size rules and entry points. No CGAL here: the Mesh_3 work is in
// mesh3_implicit.cpp and mesh3_polyhedral.cpp.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "meshing_internal.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "validate_internal.hpp"

namespace tetseg::preprocess {
namespace {

constexpr double kSurfaceDiagonalDivisor = 40.0;
constexpr double kFacetDistanceRatio = 0.1;

void require_positive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string(name) + " must be a positive number");
}

void require_non_negative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0)
    throw std::invalid_argument(std::string(name) + " must be zero or a positive number");
}

detail::Mesh3Criteria resolve(const MeshingOptions& o, double default_facet) {
  require_non_negative(o.cell_size, "cell size");
  require_non_negative(o.facet_size, "facet size");
  require_non_negative(o.facet_distance, "facet distance");
  if (!(o.facet_angle > 0.0 && o.facet_angle <= 30.0))
    throw std::invalid_argument("facet angle must be in (0, 30] degrees");
  if (!(o.cell_radius_edge_ratio >= 2.0 && std::isfinite(o.cell_radius_edge_ratio)))
    throw std::invalid_argument("cell radius-edge ratio must be at least 2");
  detail::Mesh3Criteria c;
  c.facet_angle = o.facet_angle;
  c.cell_radius_edge_ratio = o.cell_radius_edge_ratio;
  c.optimize = o.optimize;
  c.facet_size = o.facet_size > 0 ? o.facet_size : (o.cell_size > 0 ? o.cell_size : default_facet);
  c.cell_size = o.cell_size > 0 ? o.cell_size : c.facet_size;
  c.facet_distance = o.facet_distance > 0 ? o.facet_distance : kFacetDistanceRatio * c.facet_size;
  return c;
}

}  // namespace

double default_facet_size(Shape shape, const ShapeOptions& o) {
  double h = 0.0;
  switch (shape) {
    case Shape::kSphere:
      h = 0.08 * o.radius;
      break;
    case Shape::kEllipsoid:
      h = 0.06 * std::max({o.axes[0], o.axes[1], o.axes[2]});
      break;
    case Shape::kDumbbell:
      h = 0.08;
      break;
    case Shape::kPawn:
      h = 0.043;
      break;
  }
  return h / o.size;
}

double default_facet_size_for_diagonal(double diagonal) {
  return diagonal / kSurfaceDiagonalDivisor;
}

TetMesh generate_shape(Shape shape, const ShapeOptions& shape_options,
                       const MeshingOptions& meshing) {
  require_positive(shape_options.radius, "radius");
  for (double a : shape_options.axes) require_positive(a, "ellipsoid axis");
  require_positive(shape_options.size, "size");
  if (shape_options.size > 64.0) throw std::invalid_argument("size must be at most 64");
  const detail::Mesh3Criteria criteria = resolve(meshing, default_facet_size(shape, shape_options));
  TetMesh mesh = detail::mesh_implicit_shape(shape, shape_options, criteria);
  if (mesh.tets.empty()) throw std::runtime_error("meshing produced no tetrahedra");
  return mesh;
}

TetMesh tetrahedralize(const TriangleMesh& surface, const MeshingOptions& meshing,
                       const std::string& file) {
  // Pinch points (vertices where separate fans touch) are accepted here: the domain only
  // needs inside/outside queries, and the output is validated strictly by the caller.
  TriangleMesh split;
  detail::SurfaceCheck check;
  check.allow_pinched_vertices = true;
  detail::validate_closed_surface(surface, file, check, &split);
  const TriangleMesh& input = split.triangles.empty() ? surface : split;
  Vec3 lo = surface.vertices.front();
  Vec3 hi = lo;
  for (const Vec3& p : surface.vertices)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  const double diagonal =
      std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  const detail::Mesh3Criteria criteria =
      resolve(meshing, default_facet_size_for_diagonal(diagonal));
  TetMesh mesh = detail::mesh_polyhedral_surface(input, criteria);
  if (mesh.tets.empty())
    throw InputError(file,
                     "meshing produced no tetrahedra (is the surface closed and "
                     "larger than the facet size?)");
  return mesh;
}

}  // namespace tetseg::preprocess
