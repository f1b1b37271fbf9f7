#pragma once
/// \file
/// Tetrahedral meshing with CGAL Mesh_3: procedural shapes and closed surfaces. Deterministic
/// (fixed seeds, no parallel refinement): the same input and options give the same mesh.

#include <string>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// Mesh size controls, in the input's length units (procedural shapes: the shape's own
/// units, about 1 across). 0 means "derive from the bounding box" as documented in docs/cli.md.
struct MeshingOptions {
  double cell_size = 0.0;              ///< target tet edge length
  double facet_distance = 0.0;         ///< max surface approximation error
  double facet_angle = 25.0;           ///< min facet angle, degrees
  double cell_radius_edge_ratio = 3.0; ///< tet quality bound
  bool optimize = true;                ///< ODT/lloyd off, perturb + exude on
};

/// Procedural shapes made with Mesh_3's implicit domain.
enum class Shape { kSphere, kEllipsoid, kDumbbell, kPawn };

/// Parameters of the procedural shapes. `size` scales the default mesh density: 1 = default,
/// 2 = about twice as fine along an edge.
struct ShapeOptions {
  double radius = 1.0;                          ///< sphere
  double axes[3] = {1.0, 0.6, 0.3};             ///< ellipsoid semi-axes
  double size = 1.0;
};

/// Throws std::invalid_argument on an unknown name.
Shape shape_from_name(const std::string& name);

TetMesh generate_shape(Shape shape, const ShapeOptions& shape_options,
                       const MeshingOptions& meshing = {});

/// Tetrahedralises a closed, manifold surface (interior nodes included). Throws InputError
/// (naming `file`) when the surface is not usable.
TetMesh tetrahedralize(const TriangleMesh& surface, const MeshingOptions& meshing,
                       const std::string& file);

}  // namespace tetseg::preprocess
