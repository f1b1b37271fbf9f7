// Boundary extraction and volumes.

#include <catch2/catch.hpp>
#include <cmath>

#include "tetseg/preprocess/surface.hpp"

using namespace tetseg::preprocess;

namespace {

double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
         u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/// An n^3 grid of unit cubes, 6 positively oriented tets per cube (Kuhn triangulation).
TetMesh cube_grid(int n) {
  TetMesh m;
  auto id = [n](int i, int j, int k) {
    return static_cast<std::uint32_t>((i * (n + 1) + j) * (n + 1) + k);
  };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) m.nodes.push_back({double(i), double(j), double(k)});
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& p : perms) {
          int c[3] = {i, j, k};
          Tet t;
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[p[s]];
            t[static_cast<std::size_t>(s + 1)] = id(c[0], c[1], c[2]);
          }
          if (orient(m.nodes[t[0]], m.nodes[t[1]], m.nodes[t[2]], m.nodes[t[3]]) < 0)
            std::swap(t[2], t[3]);
          m.tets.push_back(t);
        }
  return m;
}

}  // namespace

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
