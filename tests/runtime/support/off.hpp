#pragma once
// A minimal OFF reader for tests (triangle meshes only), a closedness check and the
// libcgal-demo surfaces.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <utility>

#include "tetseg/testing/synthetic_scenes.hpp"
#include "tetseg/testing/test_data.hpp"

namespace tetseg::test {

/// Reads a triangle OFF file; false when unreadable or not all faces are triangles.
inline bool read_off(const std::string& path, Surface& out) {
  std::ifstream in(path);
  std::string magic;
  std::size_t nv = 0, nf = 0, ne = 0;
  if (!(in >> magic) || magic != "OFF" || !(in >> nv >> nf >> ne)) return false;
  out = Surface{};
  for (std::size_t i = 0; i < nv; ++i) {
    P3 p;
    if (!(in >> p[0] >> p[1] >> p[2])) return false;
    out.verts.push_back(p);
  }
  for (std::size_t i = 0; i < nf; ++i) {
    std::size_t k;
    format::Triangle t;
    if (!(in >> k >> t[0] >> t[1] >> t[2]) || k != 3) return false;
    if (t[0] >= nv || t[1] >= nv || t[2] >= nv) return false;
    out.tris.push_back(t);
  }
  return true;
}

/// Every undirected edge used by exactly two triangles, once in each direction.
inline bool closed_and_consistent(const Surface& s) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  for (const auto& t : s.tris)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    const auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return true;
}

/// The libcgal-demo mesh `name`.off (TETSEG_CGAL_MESH_DIR) into `out`, required closed and
/// consistent, oriented outward. False when the demo meshes are missing (have_test_data has
/// failed the test case or recorded the skip): the caller returns.
inline bool read_demo_surface(const std::string& name, Surface& out) {
  const std::string path = std::string(TETSEG_CGAL_MESH_DIR) + "/" + name + ".off";
  if (!have_test_data(path, "CGAL demo mesh")) return false;
  REQUIRE(read_off(path, out));
  REQUIRE(closed_and_consistent(out));
  orient_outward(out);
  return true;
}

/// The axis-aligned bounding box of the surface's vertices, into `lo` and `hi`.
inline void bounding_box(const Surface& s, double lo[3], double hi[3]) {
  for (int a = 0; a < 3; ++a) lo[a] = 1e300, hi[a] = -1e300;
  for (const P3& p : s.verts)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
}

/// The length of the bounding box's diagonal.
inline double bounding_diagonal(const Surface& s) {
  double lo[3], hi[3];
  bounding_box(s, lo, hi);
  return std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                   (hi[2] - lo[2]) * (hi[2] - lo[2]));
}

/// `k` clusters as slabs of equal triangle count along the longest axis (by centroid); each
/// detector is the mean of its slab's centroids (any point off the surface is sound).
inline Scene slab_scene(const Surface& s, std::uint32_t k) {
  double lo[3], hi[3];
  bounding_box(s, lo, hi);
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
  std::vector<std::pair<double, std::uint32_t>> order;
  for (std::uint32_t t = 0; t < s.tris.size(); ++t) {
    double c = 0;
    for (auto v : s.tris[t]) c += s.verts[v][axis] / 3;
    order.push_back({c, t});
  }
  std::sort(order.begin(), order.end());
  std::vector<std::uint32_t> cluster_of(s.tris.size());
  std::vector<P3> det(k, P3{0, 0, 0});
  std::vector<double> count(k, 0);
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::uint32_t c = static_cast<std::uint32_t>(i * k / order.size());
    const std::uint32_t t = order[i].second;
    cluster_of[t] = c;
    for (auto v : s.tris[t])
      for (int a = 0; a < 3; ++a) det[c][a] += s.verts[v][a] / 3;
    count[c] += 1;
  }
  for (std::uint32_t c = 0; c < k; ++c)
    for (int a = 0; a < 3; ++a) det[c][a] /= count[c];
  return make_scene(s, cluster_of, det);
}

}  // namespace tetseg::test
