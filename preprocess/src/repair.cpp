// Shape-keeping repairs of a triangle soup before meshing (`--repair fix`): degenerate and
// duplicate triangles, isolated vertices, orientation (CGAL polygon-soup processing), border
// stitching, zero-area triangles, holes (CGAL hole filling with fairing, which needs
// Eigen) and local self-intersections (CGAL local remeshing), each kept only where it keeps the
// shape.

#define CGAL_EIGEN3_ENABLED 1
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/border.h>
#include <CGAL/Polygon_mesh_processing/compute_normal.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_mesh_to_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "cgal_mesh.hpp"
#include "mesh_topology.hpp"
#include "repair_internal.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess::detail {
namespace {

using cgal::Point;
using Polygon = std::array<std::size_t, 3>;

/// Holes with at most this many border edges are filled (docs/cli.md) when the patch keeps the
/// shape (fill_holes); over kMaxSmallHoleBorderEdges, with a bounded search.
constexpr std::size_t kMaxHoleBorderEdges = 1000;
constexpr std::size_t kMaxSmallHoleBorderEdges = 64;
/// A bound on the work of large holes: the border edges of all holes over
/// kMaxSmallHoleBorderEdges that are tried (the rest are left open).
constexpr std::size_t kMaxLargeHoleWork = 4000;
/// A hole's patch may have at most this many times the area of a flat disk of the hole's
/// perimeter (a hemisphere: 2).
constexpr double kMaxPatchAreaOverDisk = 2.5;
/// A patch triangle turning by more than this against a neighbour is a fold.
constexpr double kMaxPatchTurnDegrees = 120.0;
/// Self-intersections are removed locally only up to this many intersecting pairs of
/// triangles (docs/cli.md); more is not a local defect.
constexpr std::size_t kMaxLocalSelfIntersections = 4096;
/// Self-intersection removal is kept only when the surface moved at most this much (two-sided
/// Hausdorff distance, of the bounding-box diagonal; the default --max-deviation). A folded fan
/// on a sphere (tests): 0.007; diplodocus.off 0.003; mannequin-devil.off 0.012 and bones.off
/// 0.07, refused.
constexpr double kMaxRemovalDeviation = 0.01;
/// A surface after self-intersection removal must enclose at least this volume over its area
/// to the power 3/2 (a ball: 0.094; a 1 x 1 x 0.01 plate: 0.0035).
constexpr double kMinVolumeOverArea = 1e-3;
/// Self-intersections are not removed when hole filling made more than this share of the area.
constexpr double kMaxPatchAreaForRemoval = 0.25;

using Mesh = cgal::SurfaceMesh;

/// Whether the border cycle of `border` visits each of its vertices once (a simple loop);
/// its number of edges (counting stops past kMaxHoleBorderEdges) and length into `edges` and
/// `perimeter`.
bool is_simple_border(const Mesh& mesh, Mesh::Halfedge_index border, std::size_t& edges,
                      double& perimeter) {
  std::vector<Mesh::Vertex_index> corners;
  perimeter = 0.0;
  for (const Mesh::Halfedge_index h : CGAL::halfedges_around_face(border, mesh)) {
    corners.push_back(mesh.target(h));
    perimeter +=
        std::sqrt(CGAL::squared_distance(mesh.point(mesh.source(h)), mesh.point(mesh.target(h))));
    if (corners.size() > kMaxHoleBorderEdges) break;
  }
  edges = corners.size();
  std::sort(corners.begin(), corners.end());
  return std::adjacent_find(corners.begin(), corners.end()) == corners.end();
}

/// Whether the patch `faces` folds: a patch triangle turns by more than kMaxPatchTurnDegrees
/// against a neighbour (in the patch or around the hole).
bool patch_folds(const Mesh& mesh, const std::vector<Mesh::Face_index>& faces) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  const double min_cosine = std::cos(kMaxPatchTurnDegrees * kPi / 180.0);
  for (const Mesh::Face_index f : faces) {
    const auto normal = pmp::compute_face_normal(f, mesh);
    for (const Mesh::Halfedge_index h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const Mesh::Face_index g = mesh.face(mesh.opposite(h));
      if (g == Mesh::null_face()) continue;
      if (normal * pmp::compute_face_normal(g, mesh) < min_cosine) return true;
    }
  }
  return false;
}

/// Fills the holes of `mesh` that are simple loops of at most kMaxHoleBorderEdges border edges
/// (triangulated, refined, faired: CGAL triangulate_refine_and_fair_hole; over
/// kMaxSmallHoleBorderEdges edges the cubic-time search is not used and fairing must succeed).
/// A patch is kept when it keeps the shape: no fold (patch_folds), an area of at most
/// kMaxPatchAreaOverDisk times that of a flat disk of the hole's perimeter, and no
/// intersection with the rest of the surface (then removed, the hole left open). Returns the
/// number of holes filled; adds the kept patches' area to `patch_area`.
std::size_t fill_holes(Mesh& mesh, double& patch_area) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  std::vector<Mesh::Halfedge_index> borders;
  pmp::extract_boundary_cycles(mesh, std::back_inserter(borders));
  std::vector<std::vector<Mesh::Face_index>> patches;
  const auto remove_patch = [&mesh](const std::vector<Mesh::Face_index>& faces) {
    for (const Mesh::Face_index f : faces) CGAL::Euler::remove_face(mesh.halfedge(f), mesh);
  };
  std::size_t filled = 0;
  std::size_t work = 0;  // border edges of the large holes tried
  for (const Mesh::Halfedge_index h : borders) {
    std::size_t edges = 0;
    double perimeter = 0.0;
    if (!is_simple_border(mesh, h, edges, perimeter) || edges > kMaxHoleBorderEdges) continue;
    const bool large = edges > kMaxSmallHoleBorderEdges;
    if (large && (work += edges) > kMaxLargeHoleWork) continue;
    std::vector<Mesh::Face_index> patch;
    std::vector<Mesh::Vertex_index> added;
    const bool faired = std::get<0>(pmp::triangulate_refine_and_fair_hole(
        mesh, h, std::back_inserter(patch), std::back_inserter(added),
        CGAL::parameters::do_not_use_cubic_algorithm(large)));
    if (patch.empty()) continue;
    double area = 0.0;
    for (const Mesh::Face_index f : patch) area += pmp::face_area(f, mesh);
    const double disk_area = perimeter * perimeter / (4.0 * kPi);
    if (large &&
        (!faired || !(area <= kMaxPatchAreaOverDisk * disk_area) || patch_folds(mesh, patch))) {
      remove_patch(patch);
      continue;
    }
    if (large) {
      patches.push_back(std::move(patch));
    } else {
      ++filled;
      patch_area += area;
    }
  }
  if (patches.empty()) return filled;
  // Patches crossing the rest of the surface (or each other) are removed.
  std::vector<std::size_t> patch_of(mesh.number_of_faces() + mesh.number_of_removed_faces(),
                                    SIZE_MAX);
  for (std::size_t p = 0; p < patches.size(); ++p)
    for (const Mesh::Face_index f : patches[p]) patch_of[f] = p;
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  pmp::self_intersections(mesh, std::back_inserter(pairs));
  std::vector<char> crossing(patches.size(), 0);
  for (const auto& [f, g] : pairs) {
    if (patch_of[f] != SIZE_MAX) crossing[patch_of[f]] = 1;
    if (patch_of[g] != SIZE_MAX) crossing[patch_of[g]] = 1;
  }
  for (std::size_t p = 0; p < patches.size(); ++p) {
    if (crossing[p]) {
      remove_patch(patches[p]);
      continue;
    }
    ++filled;
    for (const Mesh::Face_index f : patches[p]) patch_area += pmp::face_area(f, mesh);
  }
  mesh.collect_garbage();
  return filled;
}

std::size_t count_zero_area_faces(const Mesh& mesh) {
  std::size_t count = 0;
  for (const Mesh::Face_index f : mesh.faces())
    if (CGAL::Polygon_mesh_processing::is_degenerate_triangle_face(f, mesh)) ++count;
  return count;
}

/// Stops CGAL's self-intersection removal (checked before each round and each patch) once it
/// has started `max_patches` local remeshings (a bound on work that grows with the pairs and
/// how tangled they are), or once `*time_limit_reached` (the build's --time-limit).
struct RemovalWorkBound
    : CGAL::Polygon_mesh_processing::experimental::Remove_self_intersection_default_visitor<
          cgal::SurfaceMesh> {
  std::size_t max_patches = 0;
  std::size_t* patches = nullptr;  // shared: CGAL copies the visitor
  const std::atomic<bool>* time_limit_reached = nullptr;
  void start_component_handling() { ++*patches; }
  bool stop() const {
    return *patches >= max_patches || (time_limit_reached != nullptr && *time_limit_reached);
  }
};

/// Removes the self-intersections of `mesh` when they are local (at most
/// kMaxLocalSelfIntersections pairs of triangles): CGAL's local remeshing
/// (experimental::remove_self_intersections, at most `max_patches` local remeshings, stopped
/// at `*time_limit_reached`). The
/// result is kept only if it is closed, no intersection is left and it still encloses a
/// volume; returns the number of intersecting pairs removed (0: none, too many, or CGAL could
/// not remove them all, and `mesh` is unchanged).
std::size_t remove_local_self_intersections(Mesh& mesh, std::size_t max_patches,
                                            const std::atomic<bool>* time_limit_reached) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  std::vector<std::pair<Mesh::Face_index, Mesh::Face_index>> pairs;
  pmp::self_intersections(mesh, std::back_inserter(pairs));
  if (pairs.empty() || pairs.size() > kMaxLocalSelfIntersections) return 0;
  Mesh attempt = mesh;
  std::size_t patches = 0;
  RemovalWorkBound bound;
  bound.max_patches = max_patches;
  bound.patches = &patches;
  bound.time_limit_reached = time_limit_reached;
  try {
    if (!pmp::experimental::remove_self_intersections(attempt, CGAL::parameters::visitor(bound)))
      return 0;
  } catch (const std::exception&) {
    return 0;  // CGAL gave up on this input; the intersections are reported by validation
  }
  if (!CGAL::is_closed(attempt) || pmp::does_self_intersect(attempt)) return 0;
  // A flat sheet whose filled border folded it onto itself (libcgal-demo negative.off) comes
  // out closed but enclosing next to nothing, on which Mesh_3 never ends: refused.
  const double area = pmp::area(attempt);
  if (!(std::abs(pmp::volume(attempt)) >= kMinVolumeOverArea * area * std::sqrt(area))) return 0;
  attempt.collect_garbage();
  // Local remeshing may also cut off a part it could not mend (a thin limb): refused when the
  // surface moved further than kMaxRemovalDeviation.
  const CGAL::Bbox_3 box = pmp::bbox(mesh);
  const double diagonal =
      std::sqrt(CGAL::square(box.xmax() - box.xmin()) + CGAL::square(box.ymax() - box.ymin()) +
                CGAL::square(box.zmax() - box.zmin()));
  const auto [there, back] =
      hausdorff_distances(cgal::to_triangle_mesh(mesh), cgal::to_triangle_mesh(attempt));
  if (!(std::max(there, back) <= kMaxRemovalDeviation * diagonal)) return 0;
  mesh = std::move(attempt);
  return pairs.size();
}

/// The repairs that need the oriented soup as a polygon mesh, in this order (the hole
/// patches' area into `patch_area`): borders stitched
/// (CGAL stitch_borders: border edges whose ends coincide with another border edge's, as on a
/// seam whose vertices were duplicated), zero-area triangles removed (CGAL
/// remove_degenerate_faces, by edge collapses and flips), holes filled, local
/// self-intersections removed on a closed surface. Each count goes to `record`; the soup is
/// rewritten only when something changed.
template <class Record>
void repair_as_mesh(std::vector<Point>& points, std::vector<Polygon>& polygons,
                    const Record& record, double& patch_area, std::size_t max_removal_patches,
                    const std::atomic<bool>* time_limit_reached) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  if (polygons.empty() || !pmp::is_polygon_soup_a_polygon_mesh(polygons)) return;
  Mesh mesh;
  pmp::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  bool changed = false;
  const std::size_t stitched = pmp::stitch_borders(mesh);
  record("border edges stitched", stitched);
  changed |= stitched > 0;
  if (const std::size_t zero_area = count_zero_area_faces(mesh); zero_area > 0) {
    pmp::remove_degenerate_faces(mesh);
    mesh.collect_garbage();
    const std::size_t left = count_zero_area_faces(mesh);
    record("zero-area triangles removed", zero_area - std::min(left, zero_area));
    changed = true;
  }
  const std::size_t filled = fill_holes(mesh, patch_area);
  record("holes filled", filled);
  changed |= filled > 0;
  // Self-intersections made by the hole filling of a mostly open surface (a sheet closed onto
  // itself, libcgal-demo negative.off) are not local defects: removing them gave a lens on
  // which Mesh_3 never ended. So removal is tried only when the filled patches are under
  // kMaxPatchAreaForRemoval of the area.
  if (CGAL::is_closed(mesh) && patch_area <= kMaxPatchAreaForRemoval * pmp::area(mesh)) {
    const std::size_t removed =
        remove_local_self_intersections(mesh, max_removal_patches, time_limit_reached);
    record("self-intersecting triangle pairs removed by local remeshing", removed);
    changed |= removed > 0;
  }
  if (!changed) return;
  std::vector<Point> new_points;
  std::vector<std::vector<std::size_t>> new_polygons;
  pmp::polygon_mesh_to_polygon_soup(mesh, new_points, new_polygons);
  points = std::move(new_points);
  polygons.clear();
  for (const std::vector<std::size_t>& p : new_polygons)
    if (p.size() == 3) polygons.push_back({p[0], p[1], p[2]});
}

/// Keeps the triangles of the edge-connected component of largest area (ties: the component
/// with the smallest triangle id). Returns the number of components removed.
std::size_t keep_largest_component(const std::vector<Point>& points,
                                   std::vector<Polygon>& polygons) {
  // Triangles joined when they share an edge; a component's root is its smallest triangle id.
  UnionFind sets(static_cast<std::uint32_t>(polygons.size()));
  const auto root = [&sets](std::size_t t) { return sets.find(static_cast<std::uint32_t>(t)); };
  std::vector<std::pair<std::pair<std::size_t, std::size_t>, std::size_t>> edges;
  edges.reserve(3 * polygons.size());
  for (std::size_t t = 0; t < polygons.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t a = polygons[t][k];
      const std::size_t b = polygons[t][(k + 1) % 3];
      edges.push_back({{std::min(a, b), std::max(a, b)}, t});
    }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 1; i < edges.size(); ++i)
    if (edges[i].first == edges[i - 1].first)
      sets.unite(static_cast<std::uint32_t>(edges[i].second),
                 static_cast<std::uint32_t>(edges[i - 1].second));
  std::vector<double> area(polygons.size(), 0.0);
  for (std::size_t t = 0; t < polygons.size(); ++t) {
    const Point& a = points[polygons[t][0]];
    const Point& b = points[polygons[t][1]];
    const Point& c = points[polygons[t][2]];
    area[root(t)] += std::sqrt(CGAL::cross_product(b - a, c - a).squared_length()) / 2.0;
  }
  std::size_t kept = 0;
  std::size_t components = 0;
  for (std::size_t t = 0; t < polygons.size(); ++t) {
    if (root(t) != t) continue;
    if (components++ == 0 || area[t] > area[kept]) kept = t;
  }
  if (components <= 1) return 0;
  std::vector<Polygon> largest;
  for (std::size_t t = 0; t < polygons.size(); ++t)
    if (root(t) == kept) largest.push_back(polygons[t]);
  polygons = std::move(largest);
  return components - 1;
}

}  // namespace

std::vector<RepairCount> repair_soup(TriangleMesh& mesh, bool keep_largest, double* patch_area,
                                     std::size_t max_removal_patches,
                                     const std::atomic<bool>* time_limit_reached) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  std::vector<RepairCount> repairs;
  auto record = [&repairs](const char* kind, std::size_t count) {
    if (count > 0) repairs.push_back({kind, count});
  };
  std::vector<Point> points = cgal::to_points(mesh.vertices);
  std::vector<Polygon> polygons;
  polygons.reserve(mesh.triangles.size());
  std::size_t degenerate = 0;
  for (const Tri& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++degenerate;  // a repeated corner: no area, no orientation
      continue;
    }
    polygons.push_back({t[0], t[1], t[2]});
  }
  record("triangles with a repeated corner removed", degenerate);
  // Two triangles on the same three vertices, in either orientation, are one face.
  record("duplicate triangles removed",
         pmp::merge_duplicate_polygons_in_polygon_soup(points, polygons));
  // Orientation: triangles are flipped so that neighbours agree; a vertex where the fans
  // cannot be oriented together (a non-manifold vertex) is duplicated, once per extra fan.
  const std::vector<Polygon> before = polygons;
  const std::size_t vertices_before = points.size();
  pmp::orient_polygon_soup(points, polygons);
  std::size_t flipped = 0;
  for (std::size_t i = 0; i < polygons.size() && i < before.size(); ++i)
    if (polygons[i] != before[i]) {
      // Same corners in another cyclic order is a rotation, not a flip.
      const Polygon& a = before[i];
      const Polygon& b = polygons[i];
      const bool rotation = (b[0] == a[1] && b[1] == a[2] && b[2] == a[0]) ||
                            (b[0] == a[2] && b[1] == a[0] && b[2] == a[1]);
      if (!rotation) ++flipped;
    }
  record("triangles flipped to agree with their neighbours", flipped);
  record("non-manifold vertices duplicated", points.size() - vertices_before);
  // Vertices no triangle uses are counted before hole filling renumbers them.
  std::vector<char> used(points.size(), 0);
  for (const Polygon& polygon : polygons)
    for (std::size_t v : polygon) used[v] = 1;
  record("isolated vertices removed",
         static_cast<std::size_t>(std::count(used.begin(), used.end(), 0)));
  double patches = 0.0;
  repair_as_mesh(points, polygons, record, patches, max_removal_patches, time_limit_reached);
  if (patch_area != nullptr) *patch_area = patches;
  if (keep_largest && !polygons.empty())
    record("smaller components removed", keep_largest_component(points, polygons));
  // Vertices no triangle uses any more are dropped (ids renumbered in order).
  std::vector<std::uint32_t> new_id(points.size(), UINT32_MAX);
  TriangleMesh repaired;
  for (const Polygon& polygon : polygons) {
    Tri tri;
    for (std::size_t k = 0; k < 3; ++k) {
      std::uint32_t& id = new_id[polygon[k]];
      if (id == UINT32_MAX) {
        id = static_cast<std::uint32_t>(repaired.vertices.size());
        repaired.vertices.push_back(cgal::to_vec3(points[polygon[k]]));
      }
      tri[k] = id;
    }
    repaired.triangles.push_back(tri);
  }
  mesh = std::move(repaired);
  return repairs;
}

}  // namespace tetseg::preprocess::detail
