// Self-intersection of a closed surface with CGAL's box-intersection broad phase and exact
// predicates. The only validation unit that includes CGAL.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <iterator>
#include <vector>

#include "validate_internal.hpp"

namespace tetseg::preprocess::detail {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
namespace PMP = CGAL::Polygon_mesh_processing;

/// An output iterator that collects the pairs as face indices.
struct PairCollector {
  using iterator_category = std::output_iterator_tag;
  using value_type = void;
  using difference_type = std::ptrdiff_t;
  using pointer = void;
  using reference = void;
  std::vector<std::pair<std::size_t, std::size_t>>* out;
  PairCollector& operator*() { return *this; }
  PairCollector& operator++() { return *this; }
  PairCollector operator++(int) { return *this; }
  PairCollector& operator=(const std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>& p) {
    out->emplace_back(static_cast<std::size_t>(p.first), static_cast<std::size_t>(p.second));
    return *this;
  }
};

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> self_intersecting_pairs(
    const std::vector<Vec3>& points, const std::vector<Tri>& triangles) {
  // Compact the vertices used by the surface (a tet mesh has interior nodes).
  std::vector<std::uint32_t> local(points.size(), UINT32_MAX);
  std::vector<Point> soup_points;
  std::vector<std::array<std::size_t, 3>> soup;
  soup.reserve(triangles.size());
  for (const Tri& t : triangles) {
    std::array<std::size_t, 3> f;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& id = local[t[k]];
      if (id == UINT32_MAX) {
        id = static_cast<std::uint32_t>(soup_points.size());
        const Vec3& p = points[t[k]];
        soup_points.emplace_back(p[0], p[1], p[2]);
      }
      f[k] = id;
    }
    soup.push_back(f);
  }
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  SurfaceMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(soup_points, soup, mesh);
  if (mesh.number_of_faces() != triangles.size()) return pairs;  // caller checked manifoldness
  // Faces are created in soup order, so face index i is triangle i.
  if (!PMP::does_self_intersect(mesh)) return pairs;
  PMP::self_intersections(mesh, PairCollector{&pairs});
  for (auto& p : pairs)
    if (p.first > p.second) std::swap(p.first, p.second);
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace tetseg::preprocess::detail
