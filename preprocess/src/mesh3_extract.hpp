#pragma once
// Private, CGAL-only: shared by the Mesh_3 translation units. Turns a C3T3 into a TetMesh
// (cells in complex only, vertices compacted in order of first use, positive orientation),
// and builds the criteria and optimisation parameters. Include only from mesh3_*.cpp.

#include <CGAL/Cartesian_converter.h>
#include <CGAL/Exact_rational.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/make_mesh_3.h>

#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

#include "cgal_mesh.hpp"
#include "meshing_internal.hpp"
#include "vec3_math.hpp"

#if defined(CGAL_LINKED_WITH_TBB)
#include <tbb/global_control.h>
#endif

namespace tetseg::preprocess::detail {

/// Epick (cgal::Kernel) with one construction made robust: the power distance of a point to the
/// power sphere of four weighted points, used by Mesh_3's sliver exuder to choose vertex weights.
///
/// Why: on planar parts of a surface (a cube, the pyramid of libcgal-demo) Mesh_3 puts many
/// vertices on one plane up to rounding, and the triangulation then holds nearly flat cells
/// whose four corners and the pumped vertex all lie on that plane. Evaluated in doubles, the
/// power sphere's centre is a division by a determinant that rounds to zero, so the distance
/// comes out infinite or NaN although its exact value is small (about the squared edge
/// length). CGAL 5.5's exuder uses it unchecked: a NaN weight reaches a filtered predicate,
/// whose exact fallback converts it with gmpq_set_d, and GMP raises SIGFPE. Here a non-finite
/// double result is recomputed exactly (rationals) and rounded; an exact result beyond the
/// double range (a truly far power sphere) becomes a large finite distance, and exactly
/// coplanar corners (never in a valid triangulation) one too.
struct ExactFallbackKernel : public cgal::Kernel {
  struct Compute_power_distance_to_power_sphere_3 {
    using Weighted_point_3 = cgal::Kernel::Weighted_point_3;
    using result_type = cgal::Kernel::FT;
    double operator()(const Weighted_point_3& p, const Weighted_point_3& q,
                      const Weighted_point_3& r, const Weighted_point_3& s,
                      const Weighted_point_3& t) const {
      const double fast =
          cgal::Kernel().compute_power_distance_to_power_sphere_3_object()(p, q, r, s, t);
      if (std::isfinite(fast)) return fast;
      using Exact = CGAL::Simple_cartesian<CGAL::Exact_rational>;
      const CGAL::Cartesian_converter<cgal::Kernel, Exact> to_exact;
      const Exact::Weighted_point_3 ep = to_exact(p), eq = to_exact(q), er = to_exact(r),
                                    es = to_exact(s), et = to_exact(t);
      constexpr double kFar = std::numeric_limits<double>::max() / 8;
      if (CGAL::orientation(ep.point(), eq.point(), er.point(), es.point()) == CGAL::COPLANAR)
        return kFar;
      const double exact = CGAL::to_double(
          Exact().compute_power_distance_to_power_sphere_3_object()(ep, eq, er, es, et));
      if (!std::isfinite(exact)) return exact > 0 ? kFar : -kFar;
      return exact;
    }
  };
  Compute_power_distance_to_power_sphere_3 compute_power_distance_to_power_sphere_3_object() const {
    return {};
  }
};

template <class C3t3>
TetMesh c3t3_to_tet_mesh(const C3t3& c3t3) {
  using Tr = typename C3t3::Triangulation;
  using VertexHandle = typename Tr::Vertex_handle;
  const Tr& tr = c3t3.triangulation();
  TetMesh mesh;
  std::unordered_map<VertexHandle, std::uint32_t, CGAL::Handle_hash_function> index_of;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    Tet tet;
    for (int k = 0; k < 4; ++k) {
      const VertexHandle v = c->vertex(k);
      const auto [it, inserted] =
          index_of.emplace(v, static_cast<std::uint32_t>(mesh.nodes.size()));
      if (inserted) {
        const auto& p = tr.point(v).point();
        mesh.nodes.push_back(
            {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())});
      }
      tet[static_cast<std::size_t>(k)] = it->second;
    }
    const Vec3& a = mesh.nodes[tet[0]];
    const Vec3& b = mesh.nodes[tet[1]];
    const Vec3& c2 = mesh.nodes[tet[2]];
    const Vec3& d = mesh.nodes[tet[3]];
    const double det = detail::tet_det(a, b, c2, d);
    if (det < 0) std::swap(tet[2], tet[3]);
    mesh.tets.push_back(tet);
  }
  return mesh;
}

template <class Criteria>
Criteria make_criteria(const Mesh3Criteria& c) {
  namespace params = CGAL::parameters;
  // With protected sharp edges, a facet's vertices may lie on the edges (curves) and corners
  // bounding its patch; the edge size only matters there.
  const CGAL::Mesh_facet_topology topology =
      c.sharp_edge_angle > 0 ? CGAL::FACET_VERTICES_ON_SAME_SURFACE_PATCH_WITH_ADJACENCY_CHECK
                             : CGAL::FACET_VERTICES_ON_SAME_SURFACE_PATCH;
  return Criteria(params::edge_size = c.facet_size, params::facet_angle = c.facet_angle,
                  params::facet_size = c.facet_size, params::facet_distance = c.facet_distance,
                  params::facet_topology = topology,
                  params::cell_radius_edge_ratio = c.cell_radius_edge_ratio,
                  params::cell_size = c.cell_size);
}

/// Runs make_mesh_3 deterministically: the default random generator is reset to seed 0 and
/// the optimisers get no time limit of their own (their default limit is the refinement time,
/// which would make the result depend on the machine's speed; with a stop flag, see below).
/// Refinement uses Mesh_3's manifold option: surface facets are refined until every surface vertex
/// and edge is manifold, so the boundary of the cells in the complex is a closed 2-manifold.
/// Optimisation: sliver perturbation until every dihedral angle is at least kPerturbBoundDegrees
/// (or nothing improves), then sliver exudation; ODT and Lloyd are off.
constexpr double kPerturbBoundDegrees = 10.0;

template <class C3t3, class Domain, class Criteria>
C3t3 run_mesh_3(const Domain& domain, const Criteria& criteria, const Mesh3Criteria& options) {
  namespace params = CGAL::parameters;
  CGAL::get_default_random() = CGAL::Random(0);
  // Refinement, then the optimisers as make_mesh_3 runs them (same order, same random
  // state), called apart so that a refinement stopped at the time limit is not optimised.
  // With a stop flag the optimisers' time limit is the time left plus a second, so the flag is
  // always up when they are cut short: a run they cut short is refused below, and a returned
  // mesh never depends on the machine's speed.
  const auto stopped = [&] { return options.stop != nullptr && options.stop->load(); };
  if (stopped()) throw MeshingStopped("stopped before refinement");
  CGAL::Mesh_error_code error = CGAL::CGAL_MESH_3_NO_ERROR;
  C3t3 c3t3 = CGAL::make_mesh_3<C3t3>(
      domain, criteria, params::no_odt(), params::no_lloyd(), params::no_perturb(),
      params::no_exude(), params::manifold(),
      params::mesh_3_options(params::maximal_number_of_vertices = options.max_vertices,
                             params::pointer_to_error_code = &error,
                             params::pointer_to_stop_atomic_boolean = options.stop));
  if (error == CGAL::CGAL_MESH_3_STOPPED || stopped())
    throw MeshingStopped("stopped at the time limit in refinement");
  if (error == CGAL::CGAL_MESH_3_MAXIMAL_NUMBER_OF_VERTICES_REACHED)
    throw MeshingBudgetExceeded("refinement reached " + std::to_string(options.max_vertices) +
                                " vertices without meeting the criteria");
  const double optimiser_limit = options.stop != nullptr ? options.seconds_left + 1.0 : 0.0;
  if (options.optimize && options.perturb)
    CGAL::perturb_mesh_3(c3t3, domain, params::time_limit = optimiser_limit,
                         params::sliver_bound = kPerturbBoundDegrees);
  if (options.optimize && options.exude && !stopped())
    CGAL::exude_mesh_3(c3t3, params::time_limit = optimiser_limit, params::sliver_bound = 0);
  if (stopped()) throw MeshingStopped("stopped at the time limit in optimisation");
  return c3t3;
}

/// Meshes `domain` (run_mesh_3, then c3t3_to_tet_mesh) on Mesh_3's triangulation for the
/// concurrency `options.threads` asks for: Sequential_tag for 1; with oneTBB
/// (CGAL_LINKED_WITH_TBB), Parallel_tag under a limit of that many threads otherwise.
template <class Domain>
TetMesh mesh_domain(const Domain& domain, const Mesh3Criteria& options) {
  auto run = [&](auto concurrency) {
    using Tr = typename CGAL::Mesh_triangulation_3<Domain, ExactFallbackKernel,
                                                   decltype(concurrency)>::type;
    using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr>;
    using Criteria = CGAL::Mesh_criteria_3<Tr>;
    return c3t3_to_tet_mesh(run_mesh_3<C3t3>(domain, make_criteria<Criteria>(options), options));
  };
#if defined(CGAL_LINKED_WITH_TBB)
  if (options.threads > 1) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(options.threads));
    return run(CGAL::Parallel_tag{});
  }
#endif
  return run(CGAL::Sequential_tag{});
}

}  // namespace tetseg::preprocess::detail
