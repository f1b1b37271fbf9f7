// Approximate Hausdorff distances between two triangle surfaces: what a repair, a wrap or
// Mesh_3's re-meshing cost. The figure is CGAL's approximate_Hausdorff_distance (the largest
// distance from a fixed-seed sampling of one surface to the other), computed with less work:
// each surface is prepared once (polygon mesh, AABB tree, samples) and kept for later calls,
// a one-sided figure once measured is not measured again, and a sample's closest-point search
// stops as soon as it finds a point of the other surface within the largest distance so far
// (such a sample cannot raise the maximum), so the figure is the same.

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Random.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <memory>
#include <utility>
#include <vector>

#include "cgal_mesh.hpp"
#include "repair_internal.hpp"

namespace tetseg::preprocess::detail {
namespace {

using cgal::Kernel;
using cgal::Point;
using Mesh = cgal::SurfaceMesh;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<Mesh>;
using TreeTraits = CGAL::AABB_traits<Kernel, Primitive>;
using Tree = CGAL::AABB_tree<TreeTraits>;

/// Faces are sampled at at least this many random points (or one per vertex).
constexpr std::size_t kFaceSamples = 10000;
/// Prepared surfaces are kept for later calls (per thread) up to this many triangles in all
/// (about 200 bytes each) and this many surfaces.
constexpr std::size_t kMaxCachedTriangles = 2'000'000;
constexpr std::size_t kMaxCachedSurfaces = 3;
/// The first pass of farthest_distance takes every kFirstPassStride-th point.
constexpr std::size_t kFirstPassStride = 32;

/// The soup as a polygon mesh with the same triangles: degenerate and duplicate triangles
/// dropped, orientation made consistent and non-manifold vertices duplicated (CGAL), which
/// leaves the point set covered unchanged.
Mesh as_polygon_mesh(const TriangleMesh& soup) {
  namespace pmp = CGAL::Polygon_mesh_processing;
  std::vector<Point> points = cgal::to_points(soup.vertices);
  auto polygons = cgal::to_faces<std::vector<std::size_t>>(soup.triangles);
  pmp::repair_polygon_soup(points, polygons);
  pmp::orient_polygon_soup(points, polygons);
  Mesh mesh;
  pmp::polygon_soup_to_polygon_mesh(points, polygons, mesh);
  return mesh;
}

/// A surface prepared for distance queries; the tree and the samples are made when first
/// needed. Not movable: the tree refers to the mesh.
struct PreparedSurface {
  explicit PreparedSurface(const TriangleMesh& s) : soup(s), mesh(as_polygon_mesh(s)) {}
  PreparedSurface(const PreparedSurface&) = delete;
  PreparedSurface& operator=(const PreparedSurface&) = delete;

  TriangleMesh soup;  // what it was made from: the cache's key
  Mesh mesh;
  std::unique_ptr<Tree> tree;
  std::vector<Point> samples;  // spatially sorted
  bool sampled = false;
  /// One-sided distances measured from this surface's samples to other surfaces (their ids).
  std::vector<std::pair<std::uint64_t, double>> distance_to;
  std::uint64_t id = 0;

  const Tree& aabb_tree() {
    if (!tree) {
      tree = std::make_unique<Tree>(faces(mesh).first, faces(mesh).second, mesh);
    }
    return *tree;
  }

  /// What CGAL's approximate_Hausdorff_distance samples (sample_triangle_mesh): the vertices,
  /// random points on the faces (at least kFaceSamples, or one per vertex; seed 1) and one
  /// random point per vertex on the edges. CGAL 5.5 samples the edges with its default
  /// generator, not with random_seed: it is reseeded first, so the samples do not depend on
  /// what ran before (the time of the run).
  const std::vector<Point>& sample_points() {
    if (!sampled) {
      CGAL::get_default_random() = CGAL::Random(1);
      CGAL::Polygon_mesh_processing::sample_triangle_mesh(
          mesh, std::back_inserter(samples),
          CGAL::parameters::random_seed(1).number_of_points_on_faces(
              std::max<std::size_t>(kFaceSamples, mesh.number_of_vertices())));
      CGAL::spatial_sort(samples.begin(), samples.end());
      sampled = true;
    }
    return samples;
  }
};

/// The prepared surface of `soup`: from this thread's cache when an equal soup (same vertices
/// and triangles) was prepared recently, else made and cached.
std::shared_ptr<PreparedSurface> prepared(const TriangleMesh& soup) {
  thread_local std::vector<std::shared_ptr<PreparedSurface>> cache;  // most recent first
  thread_local std::uint64_t next_id = 1;
  for (std::size_t i = 0; i < cache.size(); ++i) {
    if (cache[i]->soup.vertices == soup.vertices && cache[i]->soup.triangles == soup.triangles) {
      std::rotate(cache.begin(), cache.begin() + static_cast<std::ptrdiff_t>(i),
                  cache.begin() + static_cast<std::ptrdiff_t>(i) + 1);
      return cache.front();
    }
  }
  auto surface = std::make_shared<PreparedSurface>(soup);
  surface->id = next_id++;
  cache.insert(cache.begin(), surface);
  std::size_t triangles = 0;
  std::size_t kept = 0;
  while (kept < cache.size() && kept < kMaxCachedSurfaces &&
         (triangles += cache[kept]->soup.triangles.size()) <= kMaxCachedTriangles)
    ++kept;
  cache.resize(kept);
  return surface;
}

/// CGAL's closest-point search (Projection_traits) that stops once the closest point found
/// lies within `squared_bound` of the query.
class ProjectionWithinBound : public CGAL::internal::AABB_tree::Projection_traits<TreeTraits> {
 public:
  ProjectionWithinBound(const cgal::Point& query, const cgal::Point& hint,
                        const TreeTraits::Primitive::Id& hint_face, const TreeTraits& traits,
                        double squared_bound)
      : Projection_traits(hint, hint_face, traits),
        m_query(query),
        m_squared_bound(squared_bound) {}
  bool go_further() const {
    return CGAL::squared_distance(m_query, closest_point()) > m_squared_bound;
  }

 private:
  cgal::Point m_query;
  double m_squared_bound;
};

/// The largest distance from `points` (spatially sorted) to the triangles of `surface`. A
/// point's search ends once a surface point within the largest distance so far is found: such a
/// point cannot raise it, so the result is the exact maximum of the closest-point distances. A
/// first pass over every kFirstPassStride-th point raises that bound early.
double farthest_distance(const std::vector<Point>& points, PreparedSurface& surface) {
  const Tree& tree = surface.aabb_tree();
  Point hint = surface.mesh.point(*surface.mesh.vertices().begin());
  const Primitive::Id hint_face = *surface.mesh.faces().begin();
  double max_squared = 0.0;
  for (const std::size_t stride : {kFirstPassStride, std::size_t{1}}) {
    for (std::size_t i = 0; i < points.size(); i += stride) {
      const Point& p = points[i];
      if (CGAL::squared_distance(p, hint) <= max_squared) continue;  // the hint is on the surface
      ProjectionWithinBound search(p, hint, hint_face, tree.traits(), max_squared);
      tree.traversal(p, search);
      hint = search.closest_point();
      max_squared = std::max(max_squared, CGAL::squared_distance(p, hint));
    }
  }
  return std::sqrt(max_squared);
}

/// The approximate Hausdorff distance from `from` to `to` (measured once per pair).
double one_sided(PreparedSurface& from, PreparedSurface& to) {
  for (const auto& [id, distance] : from.distance_to)
    if (id == to.id) return distance;
  const double distance = farthest_distance(from.sample_points(), to);
  from.distance_to.push_back({to.id, distance});
  return distance;
}

}  // namespace

std::pair<double, double> hausdorff_distances(const TriangleMesh& a, const TriangleMesh& b) {
  const std::shared_ptr<PreparedSurface> surface_a = prepared(a);
  const std::shared_ptr<PreparedSurface> surface_b = prepared(b);
  if (surface_a->mesh.is_empty() || surface_b->mesh.is_empty() ||
      surface_a->mesh.number_of_faces() == 0 || surface_b->mesh.number_of_faces() == 0)
    return {-1.0, -1.0};
  const double a_to_b = one_sided(*surface_a, *surface_b);
  return {a_to_b, one_sided(*surface_b, *surface_a)};
}

double max_distance_to_surface(const std::vector<Vec3>& points, const TriangleMesh& surface) {
  const std::shared_ptr<PreparedSurface> prepared_surface = prepared(surface);
  if (points.empty() || prepared_surface->mesh.number_of_faces() == 0) return -1.0;
  std::vector<Point> sorted = cgal::to_points(points);
  CGAL::spatial_sort(sorted.begin(), sorted.end());
  return farthest_distance(sorted, *prepared_surface);
}

}  // namespace tetseg::preprocess::detail
