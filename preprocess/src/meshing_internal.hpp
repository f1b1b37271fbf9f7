#pragma once
// Private interface between meshing.cpp (options, rules; no CGAL) and the two CGAL Mesh_3
// translation units (mesh3_implicit.cpp, mesh3_polyhedral.cpp).

#include <atomic>
#include <cstddef>
#include <stdexcept>

#include "tetseg/preprocess/meshing.hpp"

namespace tetseg::preprocess::detail {

/// Fully resolved Mesh_3 criteria (every size > 0).
struct Mesh3Criteria {
  double facet_angle = 25.0;
  double facet_size = 0.0;
  double facet_distance = 0.0;
  double cell_radius_edge_ratio = 3.0;
  double cell_size = 0.0;
  bool optimize = true;  ///< false: neither optimiser runs
  bool perturb = true;   ///< with optimize: sliver perturbation
  bool exude = true;     ///< with optimize: sliver exudation
  int threads = 1;       ///< 1: sequential (Sequential_tag); > 1: Parallel_tag on that many
  /// Refinement stops and MeshingBudgetExceeded is thrown once the triangulation has this
  /// many vertices (0: no limit). Mesh_3's manifold refinement does not always terminate
  /// (sharp corners without feature protection); the budget turns that into an error.
  std::size_t max_vertices = 0;
  /// > 0 (polyhedral surfaces only): the surface's sharp edges, those whose two triangles'
  /// normals differ by more than this many degrees, are protected (CGAL
  /// Polyhedral_mesh_domain_with_features_3, detect_features; edge size = facet_size), which
  /// Mesh_3's manifold refinement needs to terminate at sharp corners. 0: no protection.
  double sharp_edge_angle = 0.0;
  /// When set: refinement stops once it is true (CGAL pointer_to_stop_atomic_boolean) and
  /// MeshingStopped is thrown; the optimisers get `seconds_left` as their time limit.
  std::atomic<bool>* stop = nullptr;
  double seconds_left = 0.0;
};

/// Thrown by the Mesh_3 calls when Mesh3Criteria::stop was raised (the time limit).
class MeshingStopped : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Thrown by the Mesh_3 calls when refinement reached Mesh3Criteria::max_vertices.
class MeshingBudgetExceeded : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Mesh_3 on the implicit function of `shape`. Returns compacted, positively oriented tets.
TetMesh mesh_implicit_shape(Shape shape, const ShapeOptions& shape_options,
                            const Mesh3Criteria& criteria);

/// Mesh_3 on a closed, manifold, self-intersection-free triangle surface.
TetMesh mesh_polyhedral_surface(const TriangleMesh& surface, const Mesh3Criteria& criteria);

}  // namespace tetseg::preprocess::detail
