#pragma once
/// \file
/// Tetrahedral meshing with CGAL Mesh_3: procedural shapes and closed surfaces. Deterministic
/// by default (fixed seeds, sequential refinement): the same input and options give the same
/// mesh. MeshingOptions::threads > 1 trades that for speed.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// The default time limit of a build and of tetrahedralize, seconds (docs/cli.md).
inline constexpr double kDefaultTimeLimitSeconds = 600.0;

/// Mesh size controls, in the input's length units (procedural shapes: the shape's own
/// units, about 1 across). 0 means "derive" by the rule documented in docs/cli.md
/// ("## Meshing options"): facet_size from the shape (or 1/40 of the surface's bounding-box
/// diagonal), cell_size = facet_size, facet_distance = facet_size / 10.
struct MeshingOptions {
  double cell_size = 0.0;               ///< max tet circumradius (Mesh_3 cell_size); >= 0
  double facet_size = 0.0;              ///< max surface Delaunay ball radius; 0: = cell_size if set
  double facet_distance = 0.0;          ///< max surface approximation error; >= 0
  double facet_angle = 25.0;            ///< min facet angle, degrees, in (0, 30]
  double cell_radius_edge_ratio = 3.0;  ///< tet quality bound, >= 2
  bool optimize = true;  ///< sliver perturbation (10 degree bound) + exudation; no ODT/Lloyd
  /// Surfaces only: kFix repairs the input before validation; kWrap replaces it by its alpha
  /// wrap; kAuto (the default) is kFix, and kWrap when what kFix leaves cannot be meshed or
  /// when its hole patches (15 % of the area or more) lie further than max_deviation
  /// (tetrahedralize; TetrahedralizeNotes::repair_used and ::fallback_reason say which).
  enum class Repair { kNone, kFix, kWrap, kAuto } repair = Repair::kAuto;
  /// kWrap: alpha (the size of the gaps the wrap does not enter) and offset (its distance
  /// from the input), as fractions of the input's bounding-box diagonal; > 0.
  double wrap_alpha = 0.02;
  double wrap_offset = 0.002;
  /// kWrap, an input that encloses no volume (a flat or open sheet: its wrap stays a thin
  /// shell even with alpha = the diagonal): the offset, a fraction of the diagonal, of the
  /// slab (about twice as thick) it is wrapped into instead; in [1e-4, 1].
  double wrap_sheet_offset = 0.01;
  /// kFix: after the other repairs, keep only the edge-connected component of largest area
  /// (drops floating debris and stray parts); off by default, since several closed
  /// components are a valid input.
  bool keep_largest_component = false;
  /// Mesh_3 threads. 1 (default): sequential and deterministic. N > 1: Mesh_3's parallel
  /// refinement and optimisers (CGAL Parallel_tag) on N oneTBB threads; the mesh then differs
  /// from run to run (node order and tets; docs/cli.md, "Meshing options"). 0: one thread per
  /// hardware thread. Needs a build with oneTBB (meshing_threads_available()); without it,
  /// any value but 1 throws std::invalid_argument. Not recorded in an asset's provenance: an
  /// asset meshed with several threads does not rebuild byte for byte.
  int threads = 1;
  /// Surfaces only: how far the asset's surface may be from the input's (the two-sided
  /// Hausdorff distance), a fraction of the bounding-box diagonal (option_ranges
  /// kMaxDeviation). A derived facet distance is at most half of it and the wrap offset at most
  /// a quarter (the defaults are below both at 0.01); the wrap's alpha is not doubled past
  /// twice it before the slab is tried, and kAuto wraps hole patches further than it
  /// (tetrahedralize). When Mesh_3's surface lies further than it allows from the surface
  /// meshed, Mesh_3 is rerun at most twice at smaller sizes (sharp edges protected where they
  /// were rounded off), bounded in time and vertices, and the nearest mesh is kept
  /// (TetrahedralizeNotes::deviation_retries). A mesh that still deviates more (a sheet wrapped
  /// as a slab, the inner parts of a self-intersecting input) is kept, and TetrahedralizeNotes
  /// says by how much.
  double max_deviation = 0.01;
  /// Surfaces only: seconds tetrahedralize may run (0: no limit; option_ranges kTimeLimit).
  /// Mesh_3 is stopped there, and the other steps (repair, wrap, deviation) are checked
  /// between them; past it tetrahedralize throws TimeLimitExceeded naming the step. Not
  /// recorded in an asset's provenance.
  double time_limit = kDefaultTimeLimitSeconds;
  /// Surfaces only: called about every 10 s while tetrahedralize runs, from another thread,
  /// with the seconds since it started and the step it is in ("CGAL Mesh_3", ...).
  std::function<void(double seconds, const std::string& step)> progress;
};

/// Whether this build meshes in parallel (linked with oneTBB): MeshingOptions::threads != 1.
bool meshing_threads_available();

/// One kind of repair tetrahedralize made to its input, and how many.
struct RepairCount {
  std::string kind;  ///< e.g. "duplicate triangles removed" (words and spaces only)
  std::size_t count = 0;
};

/// Procedural shapes made with Mesh_3's implicit domain.
enum class Shape { kSphere, kEllipsoid, kDumbbell, kPawn };

/// Parameters of the procedural shapes. `size` scales the default mesh density: 1 = default,
/// 2 = about twice as fine along an edge.
struct ShapeOptions {
  double radius = 1.0;               ///< sphere
  double axes[3] = {1.0, 0.6, 0.3};  ///< ellipsoid semi-axes
  double size = 1.0;
};

/// A name of enum_names<Shape>() (tetseg/preprocess/names.hpp). Throws std::invalid_argument on
/// an unknown name.
Shape shape_from_name(const std::string& name);

/// Meshes a procedural shape: sphere of `radius` at the origin; ellipsoid with semi-axes
/// `axes` along x, y, z; dumbbell along x (balls of radius 0.5 at x = +-0.8, smooth neck of
/// radius 0.2); pawn of revolution about z from z = 0 to about 1.65. Returns compacted nodes
/// and positively oriented tets; deterministic. Throws std::invalid_argument on
/// non-positive or non-finite parameters. Thread safety: resets CGAL's default random
/// generator, so do not mesh concurrently from several threads.
TetMesh generate_shape(Shape shape, const ShapeOptions& shape_options,
                       const MeshingOptions& meshing = {});

/// What tetrahedralize did beyond one plain Mesh_3 run (see tetrahedralize).
struct TetrahedralizeNotes {
  /// "" when the first mesh was valid; else the retry that gave the returned mesh:
  /// "exudation only", "no optimisation", or one of those or "optimised" followed by
  /// ", sizes x0.7" or ", sizes x0.5" (every meshing size scaled by that factor).
  std::string optimization_used;
  std::string first_defect;          ///< the first mesh's boundary defect, when retried
  std::vector<RepairCount> repairs;  ///< repairs of the input (MeshingOptions::repair)
  /// The repair that gave the mesh: MeshingOptions::repair, or kFix / kWrap for kAuto.
  MeshingOptions::Repair repair_used = MeshingOptions::Repair::kNone;
  /// kAuto fell back to the wrap: why (the error of kFix, naming the defect); else "".
  std::string fallback_reason;
  /// Always measured (whatever the repair; Mesh_3 re-meshes the boundary even of a clean
  /// input): approximate Hausdorff distances between the input triangles and the boundary of
  /// the returned tets, relative to the input's bounding-box diagonal (input to mesh, mesh to
  /// input); -1 when not measured (no tets returned).
  double hausdorff_input_to_mesh = -1.0;
  double hausdorff_mesh_to_input = -1.0;
  double diagonal = 0.0;  ///< the input's bounding-box diagonal: absolute = relative x diagonal
  /// How much the larger of the two distances exceeds MeshingOptions::max_deviation (relative
  /// to the diagonal); 0 when within it.
  double deviation_excess = 0.0;
  /// Mesh_3 runs repeated at smaller sizes (at most 2) because the meshed boundary lay further
  /// than max_deviation allows from the surface meshed; 0: none. The nearest mesh is returned:
  /// deviation_retry_sizes says with which sizes ("facet distance x0.35, facet size x0.59,
  /// sharp edges protected, no sliver perturbation"), "" when the first mesh stayed the
  /// nearest.
  std::size_t deviation_retries = 0;
  std::string deviation_retry_sizes;
};

/// Tetrahedralises a closed, manifold surface (interior nodes included). With
/// `meshing.repair == kFix` the surface is first repaired without changing its shape:
/// triangles with a repeated corner removed, duplicate triangles merged, orientation made
/// consistent (flips; non-manifold vertices duplicated), borders stitched, zero-area triangles
/// collapsed, holes filled (up to 64 border edges, and up to 1000 when the patch keeps the
/// shape), up to 4096 self-intersecting pairs remeshed locally when the surface moves at most
/// 0.01 of the diagonal (docs/cli.md); the repairs go to `notes->repairs`. What is left makes
/// an error that ends by suggesting `--repair wrap`. With kWrap the surface
/// is replaced by its CGAL alpha wrap (wrap_alpha, wrap_offset), which is closed, manifold and
/// free of self-intersections for any soup; while that wrap is a thin shell (all over, or half
/// of it) or does not mesh, alpha is doubled (at most 6 times), but before alpha passes twice
/// max_deviation (or wrap_alpha when larger) the input is wrapped again with wrap_sheet_offset
/// into a slab (an open surface becomes a shell; a repair in `notes`), meshed with a 20 s bound;
/// the doublings go on only when that slab does not mesh, and an input whose wrap is still a
/// thin shell with alpha = the diagonal (a sheet) is then wrapped as that slab, unbounded. kAuto
/// is kFix, and kWrap when what fix leaves is refused (the reason in `notes`) or when fix's
/// hole patches make 15 % of the area or more and lie further than max_deviation from the
/// input (fix's surface is meshed after all when that wrap fails or lies further). `notes` gets the
/// Hausdorff distances between input and meshed boundary (always: how far the surface moved). The
/// boundary is re-meshed (Mesh_3 does not keep the input triangles); Mesh_3 runs with its manifold
/// option. Unlike validate_closed_surface, pinch points (separate fans of triangles touching at one
/// vertex position, common in modelled meshes) are accepted. The result is checked like
/// validate_tet_mesh (closed 2-manifold boundary, ...); when the optimised mesh (sliver
/// perturbation, then exudation) fails that check, meshing is retried with exudation only,
/// then without optimisation, then at 0.7 and 0.5 of every size; `notes` says which. Throws
/// InputError (naming `file`; the message starts with the stage, "tetrahedralize: ...") when
/// the surface is not usable (validate_closed_surface), a meshing size is below 1e-5 of the
/// bounding-box diagonal, CGAL throws, meshing yields no tets, or every attempt's boundary is
/// invalid (the defects are listed); std::invalid_argument on bad options. Same threading note
/// as generate_shape.
TetMesh tetrahedralize(const TriangleMesh& surface, const MeshingOptions& meshing,
                       const std::string& file, TetrahedralizeNotes* notes = nullptr);

/// "deviation 0.0012 / 0.0015 of the diagonal (input to mesh / mesh to input)" from `notes`
/// ("deviation not measured" without tets), for stage summaries.
std::string deviation_summary(const TetrahedralizeNotes& notes);

/// Default facet size (before `size` scaling) of a procedural shape, and for a surface of
/// bounding-box diagonal `diagonal`: the rules behind "0 = derive".
double default_facet_size(Shape shape, const ShapeOptions& shape_options);
double default_facet_size_for_diagonal(double diagonal);

}  // namespace tetseg::preprocess
