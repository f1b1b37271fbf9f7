#pragma once
// Private: the soup repairs of `--repair fix` (repair.cpp, CGAL polygon-soup processing), the
// alpha wrap of `--repair wrap` (alpha_wrap.cpp) and the distance they cost
// (surface_distance.cpp).

#include <atomic>
#include <cstddef>
#include <utility>
#include <vector>

#include "tetseg/preprocess/meshing.hpp"

namespace tetseg::preprocess::detail {

/// The bound on the work of CGAL's self-intersection removal (repair_soup): the local
/// remeshings (one per connected patch of intersecting triangles, per round, CGAL's default of
/// at most 7 rounds) it may start, a count, so the result does not depend on the machine's load
/// (`--time-limit` bounds the build as a whole). libcgal-demo: diplodocus.off 11 (removed, 2 s),
/// mannequin-devil.off 28 (5 s), man.off 58 (8 s), cow.off 20, bones.off 75, all within it.
constexpr std::size_t kMaxRemovalPatches = 200;

/// Repairs that keep the shape, in this order: triangles with a repeated corner removed,
/// duplicate triangles (same three vertices, either orientation) merged, orientation made
/// consistent (CGAL orient_polygon_soup: triangles flipped, non-manifold vertices
/// duplicated), borders stitched where two border edges coincide (CGAL stitch_borders),
/// zero-area triangles removed (CGAL remove_degenerate_faces), holes filled (all up to 64
/// border edges; up to 1000 when the patch keeps the shape), on a closed surface
/// self-intersections removed by local remeshing (CGAL
/// experimental::remove_self_intersections, bounded in pairs and in local remeshings,
/// `max_removal_patches`; kept only when none is left and the surface moved little), with
/// `keep_largest_component` every edge-connected component but the one of largest area
/// removed, unused vertices dropped. Returns the repairs made (kind, count; kinds with a zero
/// count are left out). Vertex ids are renumbered in order of first use. When given,
/// `patch_area` gets the area of the triangles that fill holes, and the removal stops (and is
/// not kept) once `*time_limit_reached` (the build's --time-limit, which then refuses it).
std::vector<RepairCount> repair_soup(TriangleMesh& mesh, bool keep_largest_component = false,
                                     double* patch_area = nullptr,
                                     std::size_t max_removal_patches = kMaxRemovalPatches,
                                     const std::atomic<bool>* time_limit_reached = nullptr);

/// CGAL 3D alpha wrapping of the triangle soup `soup` (any defects; at least one triangle),
/// with absolute `alpha` and `offset` (> 0): a closed, 2-manifold, self-intersection-free
/// surface enclosing the soup at about `offset` from it. May throw what CGAL throws.
TriangleMesh alpha_wrap(const TriangleMesh& soup, double alpha, double offset);

/// Approximate Hausdorff distances (the figure of CGAL approximate_Hausdorff_distance,
/// sampling vertices, edges and faces with a fixed seed: never above the true distance) from
/// `a` to `b` and from `b` to `a`, absolute; the soups may have any defects; {-1, -1} when
/// either has no usable triangle. Each thread keeps the last surfaces prepared (tree, samples)
/// and figures measured, so measuring a surface again costs a comparison of the soups.
std::pair<double, double> hausdorff_distances(const TriangleMesh& a, const TriangleMesh& b);

/// The largest distance from `points` to the triangles of `surface` (exact per point, as CGAL
/// max_distance_to_triangle_mesh), absolute; -1 without points or usable triangles.
double max_distance_to_surface(const std::vector<Vec3>& points, const TriangleMesh& surface);

}  // namespace tetseg::preprocess::detail
