// Boundary extraction and volumes.

#include <catch2/catch.hpp>
#include <cmath>

#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/preprocess/surface.hpp"

using namespace tetseg::preprocess;
using tetseg::test::cube_grid;
using tetseg::test::orient;

TEST_CASE("The boundary of a single tet is its four outward faces", "[surface]") {
  const TetMesh m{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 1, 2, 3}}};
  const Surface s = extract_surface(m);
  REQUIRE(s.triangles.size() == 4);
  CHECK(s.interior_nodes.empty());
  CHECK(s.surface_nodes == std::vector<std::uint32_t>{0, 1, 2, 3});
  SECTION("Each face's normal points away from the vertex it does not contain.") {
    for (const Tri& t : s.triangles) {
      std::uint32_t opposite = 0;
      while (opposite == t[0] || opposite == t[1] || opposite == t[2]) ++opposite;
      CHECK(orient(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[opposite]) < 0);
    }
  }
  SECTION("The enclosed volume equals the tet volume.") {
    CHECK(enclosed_volume(m.nodes, s.triangles) == Approx(1.0 / 6.0));
    CHECK(total_tet_volume(m) == Approx(1.0 / 6.0));
  }
}

TEST_CASE("The boundary of a cube grid is closed, outward and excludes interior nodes",
          "[surface]") {
  const TetMesh m = cube_grid(3);
  const Surface s = extract_surface(m);
  SECTION("Counts match the grid: 6 faces of 3x3 squares, 2 triangles each; 2^3 interior nodes.") {
    CHECK(s.triangles.size() == 6 * 9 * 2);
    CHECK(s.interior_nodes.size() == 8);
    CHECK(s.surface_nodes.size() + s.interior_nodes.size() == m.nodes.size());
    for (std::uint32_t v : s.interior_nodes)
      for (double c : m.nodes[v]) CHECK((c == 1.0 || c == 2.0));
  }
  SECTION("Every triangle lies on the cube's boundary with its normal pointing out.") {
    for (const Tri& t : s.triangles) {
      const Vec3& a = m.nodes[t[0]];
      const Vec3& b = m.nodes[t[1]];
      const Vec3& c = m.nodes[t[2]];
      const double n[3] = {(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                           (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                           (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
      const double centroid[3] = {(a[0] + b[0] + c[0]) / 3, (a[1] + b[1] + c[1]) / 3,
                                  (a[2] + b[2] + c[2]) / 3};
      double dot = 0;
      for (int k = 0; k < 3; ++k) dot += n[k] * (centroid[k] - 1.5);
      CHECK(dot > 0);
    }
  }
  SECTION("The boundary's signed volume equals the sum of tet volumes (27).") {
    CHECK(total_tet_volume(m) == Approx(27.0));
    CHECK(enclosed_volume(m.nodes, s.triangles) == Approx(27.0));
  }
  SECTION("The order is deterministic: sorted by owning tet.") {
    const Surface again = extract_surface(m);
    CHECK(again.triangles == s.triangles);
  }
}
