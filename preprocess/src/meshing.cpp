// Meshing options, size rules and entry points. No CGAL here: the Mesh_3 work is in
// mesh3_implicit.cpp and mesh3_polyhedral.cpp.

#include <algorithm>
#include <cmath>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "meshing_internal.hpp"
#include "repair_internal.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "validate_internal.hpp"

namespace tetseg::preprocess {
namespace {

constexpr double kSurfaceDiagonalDivisor = 40.0;
constexpr double kFacetDistanceRatio = 0.1;
/// Meshing sizes below diagonal / kMaxDiagonalPerSize are refused (10^5 facets along the
/// diagonal: hundreds of millions of tets, or refinement that never ends).
constexpr double kMaxDiagonalPerSize = 1e5;

double bounding_box_diagonal(const std::vector<Vec3>& points) {
  if (points.empty()) return 0.0;
  Vec3 lo = points.front();
  Vec3 hi = lo;
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  return std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

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

namespace {

/// Runs one CGAL Mesh_3 call; whatever CGAL throws becomes an InputError naming the file and
/// the stage.
TetMesh run_mesh_3_guarded(const TriangleMesh& input, const detail::Mesh3Criteria& criteria,
                           const std::string& file) {
  try {
    return detail::mesh_polyhedral_surface(input, criteria);
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw InputError(file,
                     "tetrahedralize: out of memory in CGAL Mesh_3 (is the facet size "
                     "much smaller than the surface?)");
  } catch (const std::exception& e) {
    throw InputError(file, std::string("tetrahedralize: CGAL Mesh_3 failed: ") + e.what());
  }
}

/// The defect of the tets' boundary ("" when it is a valid closed 2-manifold): the checks of
/// validate_tet_mesh.
std::string boundary_defect(const TetMesh& mesh, const std::string& file) {
  try {
    validate_tet_mesh(mesh, extract_surface(mesh), file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TetMesh tetrahedralize(const TriangleMesh& surface, const MeshingOptions& meshing,
                       const std::string& file, TetrahedralizeNotes* notes) {
  // Pinch points (vertices where separate fans touch) are accepted here: the domain only
  // needs inside/outside queries, and the output is validated strictly below.
  TriangleMesh repaired;
  if (meshing.repair == MeshingOptions::Repair::kFix) {
    repaired = surface;
    std::vector<RepairCount> repairs = detail::repair_soup(repaired);
    if (repaired.triangles.empty())
      throw InputError(file, "tetrahedralize: no triangle is left after repair");
    if (notes != nullptr) notes->repairs = std::move(repairs);
  }
  const TriangleMesh& source = meshing.repair == MeshingOptions::Repair::kFix ? repaired : surface;
  TriangleMesh split;
  detail::SurfaceCheck check;
  check.allow_pinched_vertices = true;
  detail::validate_closed_surface(source, file, check, &split);
  const TriangleMesh& input = split.triangles.empty() ? source : split;
  const double diagonal = bounding_box_diagonal(input.vertices);
  // Criteria are checked before CGAL sees them: every size finite and positive, and not so
  // small against the surface that refinement could never end (kMaxDiagonalPerSize).
  const detail::Mesh3Criteria criteria =
      resolve(meshing, default_facet_size_for_diagonal(diagonal));
  if (!(diagonal > 0.0) || !std::isfinite(diagonal))
    throw InputError(file, "tetrahedralize: the surface has no extent");
  for (const double size : {criteria.facet_size, criteria.cell_size, criteria.facet_distance})
    if (!(size * kMaxDiagonalPerSize >= diagonal))
      throw InputError(file, "tetrahedralize: a meshing size is below 1/" +
                                 std::to_string(static_cast<long>(kMaxDiagonalPerSize)) +
                                 " of the bounding-box diagonal (" + std::to_string(diagonal) +
                                 "); give larger --facet-size / --cell-size / --facet-distance");
  TetMesh mesh = run_mesh_3_guarded(input, criteria, file);
  if (mesh.tets.empty())
    throw InputError(file,
                     "meshing produced no tetrahedra (is the surface closed and "
                     "larger than the facet size?)");
  // Mesh_3 refines with its manifold option, so the boundary of the refined tets is a closed
  // 2-manifold; sliver perturbation can break that (it moves vertices after refinement: on
  // rotor, homer, couplingdown and cheese it leaves non-manifold vertices or edges), and
  // exudation alone has not been seen to. So the boundary is checked, and meshing is retried
  // with exudation only, then with no optimisation; the first valid mesh is returned.
  std::string defect = boundary_defect(mesh, file);
  if (defect.empty()) return mesh;
  std::string defects = "optimised: " + defect;
  if (criteria.optimize) {
    struct Retry {
      const char* name;
      bool exude;
    };
    for (const Retry& retry : {Retry{"exudation only", true}, Retry{"no optimisation", false}}) {
      detail::Mesh3Criteria fallback = criteria;
      fallback.perturb = false;
      fallback.optimize = retry.exude;
      mesh = run_mesh_3_guarded(input, fallback, file);
      const std::string retry_defect = boundary_defect(mesh, file);
      if (retry_defect.empty()) {
        if (notes != nullptr) {
          notes->optimization_used = retry.name;
          notes->first_defect = defect;
        }
        return mesh;
      }
      defects += std::string("; ") + retry.name + ": " + retry_defect;
    }
  }
  throw InputError(file, "tetrahedralize: the meshed boundary is not a closed 2-manifold (" +
                             defects + "); thin parts may need a smaller --facet-size");
}

}  // namespace tetseg::preprocess
