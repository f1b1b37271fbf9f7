// The self-intersection test of surface validation (BVH broad phase, CGAL's exact predicates
// on the candidate pairs) against CGAL's own Polygon_mesh_processing::self_intersections on a
// Surface_mesh, the implementation it replaced: the same pairs on every libcgal-demo mesh that
// CGAL can turn into a polygon mesh (the self-intersecting bull, camel, cow, elk, man, bones and
// ChineseDragon-10kv among them), on jittered spheres that fold through themselves, and on
// exactly touching and near-touching configurations with integer coordinates.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "../../preprocess/src/validate_internal.hpp"
#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tetseg/testing/charge_shapes.hpp"
#include "tetseg/testing/test_data.hpp"

using namespace tetseg::preprocess;

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using SurfaceMesh = CGAL::Surface_mesh<Kernel::Point_3>;
using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;
namespace PMP = CGAL::Polygon_mesh_processing;

/// CGAL's answer: the soup as a Surface_mesh (face i = triangle i), then
/// does_self_intersect and, when it says yes, self_intersections. False when CGAL cannot make the
/// soup a mesh.
bool cgal_pairs(const std::vector<Vec3>& points, const std::vector<Tri>& triangles, Pairs& out,
                bool& intersects) {
  std::vector<Kernel::Point_3> soup_points;
  for (const Vec3& p : points) soup_points.emplace_back(p[0], p[1], p[2]);
  std::vector<std::array<std::size_t, 3>> soup;
  for (const Tri& t : triangles) soup.push_back({t[0], t[1], t[2]});
  if (!PMP::is_polygon_soup_a_polygon_mesh(soup)) return false;
  SurfaceMesh mesh;
  PMP::polygon_soup_to_polygon_mesh(soup_points, soup, mesh);
  if (mesh.number_of_faces() != triangles.size()) return false;
  intersects = PMP::does_self_intersect(mesh);
  out.clear();
  if (!intersects) return true;  // as validation did before (self_intersections agrees)
  std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> faces;
  PMP::self_intersections(mesh, std::back_inserter(faces));
  for (const auto& [f, g] : faces)
    out.emplace_back(std::min<std::size_t>(f, g), std::max<std::size_t>(f, g));
  std::sort(out.begin(), out.end());
  return true;
}

/// A soup CGAL cannot make a mesh of, made into one by CGAL's orient_polygon_soup (which
/// duplicates non-manifold vertices and flips triangles); false when that fails too.
bool oriented_soup(std::vector<Vec3>& points, std::vector<Tri>& triangles) {
  std::vector<Kernel::Point_3> soup_points;
  for (const Vec3& p : points) soup_points.emplace_back(p[0], p[1], p[2]);
  std::vector<std::vector<std::size_t>> soup;
  for (const Tri& t : triangles) soup.push_back({t[0], t[1], t[2]});
  PMP::orient_polygon_soup(soup_points, soup);
  points.clear();
  for (const auto& p : soup_points) points.push_back({p.x(), p.y(), p.z()});
  triangles.clear();
  for (const auto& f : soup) {
    if (f.size() != 3) return false;
    triangles.push_back({static_cast<std::uint32_t>(f[0]), static_cast<std::uint32_t>(f[1]),
                         static_cast<std::uint32_t>(f[2])});
  }
  return true;
}

/// Checks detail::self_intersecting_pairs against CGAL; returns the pair count (-1 when CGAL
/// cannot build the mesh).
long compare_with_cgal(const std::vector<Vec3>& points, const std::vector<Tri>& triangles) {
  Pairs expected;
  bool intersects = false;
  if (!cgal_pairs(points, triangles, expected, intersects)) return -1;
  const Pairs found = detail::self_intersecting_pairs(points, triangles);
  CHECK(found == expected);
  CHECK(intersects == !found.empty());
  return static_cast<long>(found.size());
}

/// The closed surface of the axis box [lo, hi] (12 triangles, outward), vertices appended.
void add_box(std::vector<Vec3>& points, std::vector<Tri>& triangles, const Vec3& lo,
             const Vec3& hi) {
  const std::uint32_t base = static_cast<std::uint32_t>(points.size());
  for (int i = 0; i < 8; ++i)
    points.push_back({(i & 1) ? hi[0] : lo[0], (i & 2) ? hi[1] : lo[1], (i & 4) ? hi[2] : lo[2]});
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    triangles.push_back({base + q[0], base + q[1], base + q[2]});
    triangles.push_back({base + q[0], base + q[2], base + q[3]});
  }
}

}  // namespace

TEST_CASE("Self-intersection pairs equal CGAL's on the libcgal-demo meshes",
          "[validate][cgal][slow]") {
  const std::string dir = TETSEG_CGAL_MESH_DIR;
  if (!tetseg::test::have_test_data(dir, "libcgal-demo meshes")) return;
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".off") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  std::size_t compared = 0, intersecting = 0;
  std::vector<std::string> seen_intersecting;
  for (const std::string& name : names) {
    CAPTURE(name);
    TriangleMesh mesh;
    try {
      mesh = read_triangle_mesh(dir + "/" + name + ".off");
    } catch (const std::exception&) {
      continue;  // not a triangle mesh this reader accepts (polygons, empty files)
    }
    if (mesh.triangles.empty() || mesh.triangles.size() > 200000) continue;
    long count = compare_with_cgal(mesh.vertices, mesh.triangles);
    if (count < 0 && oriented_soup(mesh.vertices, mesh.triangles))
      count = compare_with_cgal(mesh.vertices, mesh.triangles);
    if (count < 0) continue;
    ++compared;
    if (count > 0) {
      ++intersecting;
      seen_intersecting.push_back(name);
    }
  }
  // The corpus's known self-intersecting meshes were all compared.
  for (const char* name : {"bull", "camel", "cow", "elk", "man", "bones", "ChineseDragon-10kv"}) {
    CAPTURE(name);
    CHECK(std::find(seen_intersecting.begin(), seen_intersecting.end(), name) !=
          seen_intersecting.end());
  }
  INFO(compared << " meshes compared, " << intersecting << " self-intersect");
  CHECK(compared >= 60);
  CHECK(intersecting < compared);
}

TEST_CASE("Self-intersection pairs equal CGAL's on spheres folded by jitter", "[validate]") {
  std::mt19937_64 random(5);
  std::size_t with_pairs = 0;
  for (int round = 0; round < 40; ++round) {
    CAPTURE(round);
    TriangleMesh sphere = tetseg::test::icosphere(3 + round % 3);
    std::normal_distribution<double> jitter(0.0, round < 20 ? 0.02 : 0.15);
    for (Vec3& p : sphere.vertices)
      for (double& c : p) c += jitter(random);
    if (compare_with_cgal(sphere.vertices, sphere.triangles) > 0) ++with_pairs;
  }
  // Both outcomes occur: the comparison covers intersecting and clean surfaces.
  CHECK(with_pairs > 5);
  CHECK(with_pairs < 40);
}

TEST_CASE("Self-intersection pairs equal CGAL's on exactly touching and near-touching boxes",
          "[validate]") {
  // Two unit boxes, the second offset by `shift` (integer coordinates: every contact exact).
  // Shared positions with distinct vertex ids touch, so they count, as in CGAL.
  const std::vector<Vec3> shifts = {
      {3, 0, 0},         // apart: no pair
      {1, 0, 0},         // face against face
      {1, 1, 0},         // edge against edge
      {1, 1, 1},         // corner against corner
      {1, 0.5, 0.5},     // face against face, offset
      {0.5, 0.5, 0.5},   // overlapping volumes
      {1 + 1e-12, 0, 0}  // a gap of 1e-12: no pair
  };
  for (const Vec3& shift : shifts) {
    CAPTURE(shift[0], shift[1], shift[2]);
    std::vector<Vec3> points;
    std::vector<Tri> triangles;
    add_box(points, triangles, {0, 0, 0}, {1, 1, 1});
    add_box(points, triangles, shift, {shift[0] + 1, shift[1] + 1, shift[2] + 1});
    const long count = compare_with_cgal(points, triangles);
    CHECK(count >= 0);
    CHECK((count == 0) == (shift[0] > 1));
  }
  // One box alone: coplanar neighbours across the face diagonals and shared corners are not
  // intersections.
  std::vector<Vec3> points;
  std::vector<Tri> triangles;
  add_box(points, triangles, {0, 0, 0}, {1, 1, 1});
  CHECK(compare_with_cgal(points, triangles) == 0);
  // A corner pushed through the opposite face (shared-vertex and shared-edge pairs that do
  // overlap), and pushed exactly onto it (touching).
  for (const double depth : {2.0, 1.0, 0.999999}) {
    CAPTURE(depth);
    std::vector<Vec3> folded = points;
    folded[7] = {1 - depth, 1 - depth, 1 - depth};
    const long count = compare_with_cgal(folded, triangles);
    CHECK(count >= 0);
  }
  // A flat fold: one triangle of a face turned over onto its neighbour (shared edge, coplanar,
  // apexes on the same side).
  std::vector<Vec3> flat = points;
  flat[3] = {1, -1, 0};
  CHECK(compare_with_cgal(flat, triangles) > 0);
}

// Hidden benchmark: CGAL's test (soup to Surface_mesh, does_self_intersect) against
// detail::self_intersecting_pairs on the boundary of the 93^3 grid of the scale benchmark
// (103,788 triangles on six flat faces) and on an icosphere of 103,680 triangles. Prints the
// best of three, wall and process CPU; asserts only that the answers agree.
TEST_CASE("Benchmark: self-intersection test, CGAL's and the validation's",
          "[.bench][selfx-bench]") {
  constexpr int kCells = 93;
  std::mt19937_64 random(17);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  const TetMesh grid = tetseg::test::kuhn_grid(kCells, kCells, kCells, [&](int i, int j, int k) {
    Vec3 p;
    const int c[3] = {i, j, k};
    for (int a = 0; a < 3; ++a)
      p[a] = (c[a] + (c[a] == 0 || c[a] == kCells ? 0.0 : jitter(random))) / kCells;
    return p;
  });
  const TriangleMesh sphere = tetseg::test::icosphere(72);
  struct Case {
    const char* name;
    const std::vector<Vec3>& points;
    std::vector<Tri> triangles;
  };
  const Case cases[] = {{"grid boundary", grid.nodes, extract_surface(grid).triangles},
                        {"icosphere", sphere.vertices, sphere.triangles}};
  for (const Case& c : cases) {
    auto best = [](auto&& work) {
      double wall = 1e300, cpu = 1e300;
      for (int run = 0; run < 3; ++run) {
        const auto start = std::chrono::steady_clock::now();
        const std::clock_t cpu_start = std::clock();
        work();
        cpu = std::min(cpu, static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC);
        wall = std::min(
            wall, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
      return std::make_pair(wall, cpu);
    };
    Pairs expected, found;
    bool intersects = true;
    const auto cgal = best([&] { cgal_pairs(c.points, c.triangles, expected, intersects); });
    const auto ours = best([&] { found = detail::self_intersecting_pairs(c.points, c.triangles); });
    std::printf(
        "%s, %zu triangles: CGAL wall %.3f s cpu %.3f s; validation wall %.3f s cpu %.3f s\n",
        c.name, c.triangles.size(), cgal.first, cgal.second, ours.first, ours.second);
    CHECK(found == expected);
    CHECK_FALSE(intersects);
  }
}
