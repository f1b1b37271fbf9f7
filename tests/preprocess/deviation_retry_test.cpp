// Issue 28, item 5: when the meshed surface lies further than --max-deviation from the input,
// Mesh_3 is rerun at smaller sizes (sharp edges protected where they were rounded off) and the
// nearest mesh is kept; when the retries cannot meet it, the report says by how much. Checked
// against the analytic surfaces of a sphere and a cube, not against the library's own distance.

#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "preprocess/support/mesh_measures.hpp"
#include "tetseg/preprocess/jobs.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tetseg/testing/charge_shapes.hpp"

using namespace tetseg::preprocess;

namespace {

Vec3 lerp(const Vec3& a, const Vec3& b, double t) {
  return {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
}

/// Points on the boundary of `mesh`: its vertices, edge midpoints and triangle centroids.
std::vector<Vec3> boundary_samples(const TetMesh& mesh) {
  std::vector<Vec3> points;
  for (const Tri& t : extract_surface(mesh).triangles) {
    const Vec3 &a = mesh.nodes[t[0]], &b = mesh.nodes[t[1]], &c = mesh.nodes[t[2]];
    points.insert(points.end(),
                  {a,
                   lerp(a, b, 0.5),
                   lerp(b, c, 0.5),
                   lerp(c, a, 0.5),
                   {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3, (a[2] + b[2] + c[2]) / 3}});
  }
  return points;
}

/// The unit cube [0, 1]^3 with each face split into n x n squares of two outward triangles,
/// vertices shared: edges 1/n long, so its sharp edges are not protected at default sizes.
TriangleMesh subdivided_cube(int n) {
  TriangleMesh s;
  std::map<std::array<int, 3>, std::uint32_t> id;
  const auto vertex = [&](std::array<int, 3> g) {
    const auto [it, added] = id.emplace(g, static_cast<std::uint32_t>(s.vertices.size()));
    if (added) s.vertices.push_back({double(g[0]) / n, double(g[1]) / n, double(g[2]) / n});
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (const int side : {0, n}) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          std::array<std::uint32_t, 4> q;
          const int corner[4][2] = {{i, j}, {i + 1, j}, {i + 1, j + 1}, {i, j + 1}};
          for (int k = 0; k < 4; ++k) {
            std::array<int, 3> g{};
            g[axis] = side;
            g[u] = corner[k][0];
            g[w] = corner[k][1];
            q[k] = vertex(g);
          }
          if (side == n) {
            s.triangles.push_back({q[0], q[1], q[2]});
            s.triangles.push_back({q[0], q[2], q[3]});
          } else {
            s.triangles.push_back({q[0], q[2], q[1]});
            s.triangles.push_back({q[0], q[3], q[2]});
          }
        }
    }
  return s;
}

/// Distance from `p` to the surface of the unit cube [0, 1]^3.
double distance_to_unit_cube(const Vec3& p) {
  double outside = 0.0, inside = 1.0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max(-p[k], p[k] - 1.0);
    if (d > 0) outside += d * d;
    inside = std::min(inside, -d);
  }
  return outside > 0 ? std::sqrt(outside) : inside;
}

using tetseg::test::diagonal_of;
using tetseg::test::squared_distance_to_triangle;

/// The largest distance from points on the twelve edges of the unit cube to the boundary of
/// `mesh` (brute force): how far the mesh rounded them off.
double cube_edges_to_mesh(const TetMesh& mesh) {
  const std::vector<Tri> boundary = extract_surface(mesh).triangles;
  double largest = 0.0;
  for (int axis = 0; axis < 3; ++axis)
    for (const double u : {0.0, 1.0})
      for (const double w : {0.0, 1.0})
        for (int k = 0; k <= 20; ++k) {
          Vec3 p;
          p[axis] = k / 20.0;
          p[(axis + 1) % 3] = u;
          p[(axis + 2) % 3] = w;
          double nearest_squared = 1e300;
          for (const Tri& t : boundary)
            nearest_squared = std::min(
                nearest_squared, squared_distance_to_triangle(p, mesh.nodes[t[0]], mesh.nodes[t[1]],
                                                              mesh.nodes[t[2]]));
          largest = std::max(largest, std::sqrt(nearest_squared));
        }
  return largest;
}

}  // namespace

TEST_CASE("A deviation retry brings a sphere within --max-deviation (analytic distance)",
          "[deviation][max-deviation][retry]") {
  // An explicit facet size of 0.5 (chords 0.03 from the unit sphere, 0.009 of the diagonal)
  // and facet distance of 0.02 of the diagonal leave Mesh_3's surface over --max-deviation
  // 0.002: the retries mesh again at smaller sizes. The input (5120 triangles on the unit sphere)
  // is itself within its chord error, 1 - cos(edge / 2) < 2.2e-4, of the analytic sphere; the
  // mesh's vertices, edge midpoints and centroids must lie within 0.002 of the diagonal of it, plus
  // that chord error.
  const TriangleMesh sphere = tetseg::test::icosphere(32);
  MeshingOptions meshing;
  meshing.optimize = false;
  meshing.max_deviation = 0.002;
  meshing.facet_size = 0.5;
  meshing.facet_distance = 0.02 * diagonal_of(sphere);
  TetrahedralizeNotes notes;
  const TetMesh mesh = tetrahedralize(sphere, meshing, "ball.off", &notes);
  CHECK(notes.deviation_retries >= 1);
  CHECK(notes.deviation_retry_sizes.find("facet distance x") == 0);
  CHECK(notes.deviation_excess == 0.0);
  double farthest = 0.0;
  for (const Vec3& p : boundary_samples(mesh))
    farthest = std::max(farthest, std::fabs(std::hypot(p[0], p[1], p[2]) - 1.0));
  CHECK(farthest <= 0.002 * notes.diagonal + 2.2e-4);
  CHECK(farthest > 0.0);  // re-meshed, not the input returned
}

TEST_CASE("A deviation retry protects the sharp edges Mesh_3 rounded off (analytic cube)",
          "[deviation][max-deviation][retry]") {
  // A finely tessellated unit cube (edges 1/12, under 8 facet sizes) is meshed without
  // sharp-edge protection first; Mesh_3 cuts its edges and corners off by about 0.006 of the
  // diagonal, over 0.004. The retry protects the sharp edges: the cube's edges are then on the
  // mesh, and every point of the mesh's boundary is on the cube's faces.
  const TriangleMesh cube = subdivided_cube(12);
  MeshingOptions meshing;  // optimised: without, the protected mesh takes the size retries
  meshing.max_deviation = 0.004;
  TetrahedralizeNotes notes;
  const TetMesh mesh = tetrahedralize(cube, meshing, "cube.off", &notes);
  const double allowed = 0.004 * std::sqrt(3.0);  // absolute: the diagonal is sqrt 3
  CHECK(notes.deviation_retries >= 1);
  CHECK(notes.deviation_retry_sizes.find("sharp edges protected") != std::string::npos);
  CHECK(notes.deviation_excess == 0.0);
  double farthest = 0.0;
  for (const Vec3& p : boundary_samples(mesh))
    farthest = std::max(farthest, std::fabs(distance_to_unit_cube(p)));
  CHECK(farthest <= allowed);
  // Protected, the edges are sampled exactly and joined by straight segments: no rounding.
  // (Smaller sizes alone bring the cube within 0.004 too, with its edges rounded off.)
  CHECK(cube_edges_to_mesh(mesh) <= 1e-9);
}

TEST_CASE("When the retries cannot meet --max-deviation, the report says by how much",
          "[deviation][max-deviation][retry]") {
  // Facet distance 0.02 of the diagonal against --max-deviation 0.0005: each retry shrinks the
  // facet distance at most 4 times, so two retries leave the sphere about 0.001 away. The
  // nearest mesh is kept, and the excess is its distance minus 0.0005, in the notes, the
  // report and the provenance.
  const TriangleMesh sphere = tetseg::test::icosphere(16);
  BuildJobOptions options;
  options.build.clusters = ClusterMethod::kSingle;
  options.meshing.optimize = false;
  options.meshing.max_deviation = 0.0005;
  options.meshing.facet_distance = 0.02 * diagonal_of(sphere);
  options.meshing.cell_size = 0.5;
  const BuildJobResult result = build_asset_from_surface(sphere, "ball.off", options);
  const TetrahedralizeNotes& notes = result.meshing_notes;
  const double larger = std::max(notes.hausdorff_input_to_mesh, notes.hausdorff_mesh_to_input);
  CHECK(notes.deviation_retries == 2);
  CHECK(larger > 0.0005);
  CHECK(larger < 0.005);  // the retries got it far nearer than the first mesh, about 0.02
  CHECK(notes.deviation_excess == Approx(larger - 0.0005).margin(1e-12));
  const std::string report = build_report_json(result, "ball.off", "");
  CHECK(report.find("\"deviation_retries\": 2") != std::string::npos);
  const std::size_t at = report.find("\"deviation_excess\": ");
  REQUIRE(at != std::string::npos);
  CHECK(std::stod(report.substr(at + 20)) == Approx(notes.deviation_excess).epsilon(1e-6));
  std::string recorded;
  for (const auto& [key, value] : result.asset.provenance.options)
    if (key == "deviation.excess") recorded = value;
  REQUIRE_FALSE(recorded.empty());
  CHECK(std::stod(recorded) == Approx(notes.deviation_excess).epsilon(1e-9));
}

TEST_CASE("No retry when the wrap alone lies further than --max-deviation from the input",
          "[deviation][max-deviation][retry]") {
  // Two interpenetrating spheres of radius 1, centres 1 apart: their wrap is the union, and
  // each sphere's cap inside the other reaches the other's centre, 1 from the union's surface,
  // far over --max-deviation 0.002 of the diagonal. Smaller Mesh_3 sizes cannot bring the mesh
  // nearer the input than the wrap itself: no retry is spent.
  TriangleMesh pair = tetseg::test::icosphere(3);
  const TriangleMesh second = tetseg::test::icosphere(3);
  const auto first_count = static_cast<std::uint32_t>(pair.vertices.size());
  for (Vec3 v : second.vertices) pair.vertices.push_back({v[0] + 1.0, v[1], v[2]});
  for (Tri t : second.triangles)
    pair.triangles.push_back({t[0] + first_count, t[1] + first_count, t[2] + first_count});
  BuildJobOptions options;
  options.build.clusters = ClusterMethod::kSingle;
  options.meshing.optimize = false;
  options.meshing.repair = MeshingOptions::Repair::kWrap;
  options.meshing.max_deviation = 0.002;
  const BuildJobResult result = build_asset_from_surface(pair, "spheres.off", options);
  const TetrahedralizeNotes& notes = result.meshing_notes;
  const double larger = std::max(notes.hausdorff_input_to_mesh, notes.hausdorff_mesh_to_input);
  // The caps' poles are 1 inside the union (0.9 allows for the polygons), and the diagonal
  // is sqrt(3^2 + 2^2 + 2^2).
  CHECK(larger > 0.9 / std::sqrt(17.0));
  CHECK(notes.deviation_retries == 0);
  CHECK(notes.deviation_excess == Approx(larger - 0.002).margin(1e-12));
}

TEST_CASE("A retry expected to pass the retries' vertex bound is not run",
          "[deviation][max-deviation][retry]") {
  // A small cell size fills the unit ball with about 35k vertices; the facet size 0.5 and
  // distance 0.02 of the diagonal leave the surface over --max-deviation 0.0005. A retry would make
  // at least the first mesh's vertices / 0.7 (its facet distance shrinks at least that much), over
  // the 40k the retries may make (meshing.cpp, kMaxRetryVertices): none is run, and the excess is
  // reported. The same ball with a cell size 1.5 times larger (about 10k vertices) is retried.
  const TriangleMesh sphere = tetseg::test::icosphere(16);
  MeshingOptions meshing;
  meshing.optimize = false;
  meshing.max_deviation = 0.0005;
  meshing.facet_size = 0.5;
  meshing.facet_distance = 0.02 * diagonal_of(sphere);
  meshing.cell_size = 0.045;
  TetrahedralizeNotes notes;
  const TetMesh mesh = tetrahedralize(sphere, meshing, "ball.off", &notes);
  INFO("first mesh: " << mesh.nodes.size() << " vertices");
  CHECK(mesh.nodes.size() > 40000 * 0.7);
  CHECK(notes.deviation_retries == 0);
  CHECK(notes.deviation_excess > 0.0);
  meshing.cell_size = 0.045 * 1.5;
  TetrahedralizeNotes coarser_notes;
  const TetMesh coarser = tetrahedralize(sphere, meshing, "ball.off", &coarser_notes);
  INFO("coarser first mesh: " << coarser.nodes.size() << " vertices");
  CHECK(coarser_notes.deviation_retries >= 1);
}

TEST_CASE("Sharp edges in many curves: the first retry leaves them unprotected",
          "[deviation][max-deviation][retry]") {
  // 18 finely tessellated unit cubes (a 3 x 3 x 2 grid, 0.5 apart): their sharp edges form 18
  // curves, over the 16 a retry protects at once (CAD parts have fewer; tessellation noise on
  // organic scans many more). Mesh_3 rounds their edges off over --max-deviation 0.004; the
  // first retry, unprotected at smaller sizes, meets it (as for one such cube; the single cube
  // above, one curve, is protected at once).
  const TriangleMesh cube = subdivided_cube(8);
  TriangleMesh cubes;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 2; ++k) {
        const auto offset = static_cast<std::uint32_t>(cubes.vertices.size());
        for (const Vec3& v : cube.vertices)
          cubes.vertices.push_back({v[0] + 1.5 * i, v[1] + 1.5 * j, v[2] + 1.5 * k});
        for (const Tri& t : cube.triangles)
          cubes.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
      }
  MeshingOptions meshing;
  meshing.optimize = false;
  meshing.max_deviation = 0.004;
  TetrahedralizeNotes notes;
  tetrahedralize(cubes, meshing, "cubes.off", &notes);
  CHECK(notes.deviation_retries == 1);  // protected at once, it takes two, or stays protected
  CHECK(notes.deviation_retry_sizes.find("facet distance x") == 0);
  CHECK(notes.deviation_retry_sizes.find("sharp edges protected") == std::string::npos);
  CHECK(notes.deviation_excess == 0.0);
}

TEST_CASE("A build with deviation retries gives the same tets twice",
          "[deviation][max-deviation][retry][determinism]") {
  // The retries are bounded by vertex counts, not seconds: the same input gives the same mesh
  // whatever the machine's load (with a time bound, a retry near it came out either way).
  const TriangleMesh sphere = tetseg::test::icosphere(16);
  MeshingOptions meshing;
  meshing.max_deviation = 0.002;
  meshing.facet_size = 0.5;
  meshing.facet_distance = 0.02 * diagonal_of(sphere);
  TetrahedralizeNotes first_notes, second_notes;
  const TetMesh first = tetrahedralize(sphere, meshing, "ball.off", &first_notes);
  const TetMesh second = tetrahedralize(sphere, meshing, "ball.off", &second_notes);
  CHECK(first_notes.deviation_retries >= 1);
  CHECK(first.nodes == second.nodes);
  CHECK(first.tets == second.tets);
  CHECK(first_notes.hausdorff_input_to_mesh == second_notes.hausdorff_input_to_mesh);
  CHECK(first_notes.hausdorff_mesh_to_input == second_notes.hausdorff_mesh_to_input);
}

TEST_CASE("The deviation is measured against the input, not the surface fix made of it",
          "[deviation][max-deviation]") {
  // A unit sphere with a cap of angular radius 0.3 cut off: fix fills the hole (about 2 % of
  // the area, so auto keeps the patch), and the mesh's surface over the patch lies about
  // sin(0.3) from the input's rim. The retry check measures the mesh against the fixed
  // surface (near 0 there); only where fix changed nothing may its figure be the report's.
  const TriangleMesh full = tetseg::test::icosphere(8);
  TriangleMesh open;
  open.vertices = full.vertices;
  for (const Tri& t : full.triangles) {
    double z = 0.0;
    for (int k = 0; k < 3; ++k) z += full.vertices[t[k]][2] / 3.0;
    if (z < std::cos(0.3)) open.triangles.push_back(t);
  }
  REQUIRE(open.triangles.size() < full.triangles.size());
  TetrahedralizeNotes notes;
  tetrahedralize(open, MeshingOptions{}, "capless.off", &notes);
  REQUIRE_FALSE(notes.repairs.empty());  // the hole filled
  CHECK(notes.repair_used == MeshingOptions::Repair::kFix);
  const double rim = std::sin(0.3) / notes.diagonal;  // from the patch's centre, relative
  CHECK(notes.hausdorff_mesh_to_input > 0.7 * rim);
  CHECK(notes.hausdorff_mesh_to_input < 1.1 * rim);
}
