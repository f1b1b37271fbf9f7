// Validation of tet meshes and closed surfaces: one test per defect, checking the message.

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/preprocess/surface.hpp"

using namespace tetseg::preprocess;

namespace {

TetMesh block(int n) {
  return tetseg::test::cube_grid(n);
}

std::string tet_error(const TetMesh& m) {
  try {
    validate_tet_mesh(m, extract_surface(m), "m.mesh");
  } catch (const InputError& e) {
    CHECK(e.file() == "m.mesh");
    return e.what();
  }
  return "(valid)";
}

std::string surface_error(const TriangleMesh& m) {
  try {
    validate_closed_surface(m, "s.obj");
  } catch (const InputError& e) {
    CHECK(e.file() == "s.obj");
    return e.what();
  }
  return "(valid)";
}

/// The boundary of block(n) as a triangle mesh over the block's nodes.
TriangleMesh block_surface(int n) {
  const TetMesh m = block(n);
  return TriangleMesh{m.nodes, extract_surface(m).triangles};
}

/// Appends `b` to `a` (nodes renumbered), as one mesh.
TetMesh join(TetMesh a, const TetMesh& b) {
  const auto offset = static_cast<std::uint32_t>(a.nodes.size());
  a.nodes.insert(a.nodes.end(), b.nodes.begin(), b.nodes.end());
  for (Tet t : b.tets) {
    for (auto& v : t) v += offset;
    a.tets.push_back(t);
  }
  return a;
}

}  // namespace

TEST_CASE("Valid meshes pass validation", "[validate]") {
  CHECK(tet_error(block(3)) == "(valid)");
  CHECK(surface_error(block_surface(2)) == "(valid)");
}

TEST_CASE("Each tet mesh defect is reported with a clear message", "[validate]") {
  TetMesh m = block(2);
  SECTION("A node index out of range is reported with the tet and the node.") {
    m.tets[4][2] = 1000;
    CHECK_THAT(tet_error(m), Catch::Contains("tet 4 refers to node 1000 out of range (27 nodes)"));
  }
  SECTION("A NaN coordinate is reported with the node.") {
    m.nodes[5][1] = std::numeric_limits<double>::quiet_NaN();
    CHECK_THAT(tet_error(m), Catch::Contains("node 5 has a non-finite coordinate"));
  }
  SECTION("An inverted tet is counted and the first one named.") {
    std::swap(m.tets[7][0], m.tets[7][1]);
    std::swap(m.tets[9][0], m.tets[9][1]);
    CHECK_THAT(tet_error(m), Catch::Contains("2 inverted tets (negative volume), first is tet 7"));
  }
  SECTION("A degenerate tet (four coplanar nodes) is reported.") {
    m.tets.push_back({0, 3, 9, 12});  // all on the face x = 0
    CHECK_THAT(tet_error(m), Catch::Contains("1 degenerate tet (zero volume), first is tet 48"));
  }
  SECTION("A nearly flat tet below the relative threshold is degenerate; above it is not.") {
    TetMesh t{{{0, 0, 0}, {1e3, 0, 0}, {0, 1e3, 0}, {0, 0, 1e-10}}, {{0, 1, 2, 3}}};
    CHECK_THAT(tet_error(t), Catch::Contains("degenerate"));
    t.nodes[3][2] = 1e-3;
    CHECK(tet_error(t) == "(valid)");
  }
  SECTION("A boundary triangle too thin for charge is refused; a thicker one is not.") {
    // A tet of non-zero volume (above the degenerate-tet threshold) whose face (0, 1, 2) is a
    // sliver: area 5e-12, under 1e-10 x its longest edge (1) squared, as charge refuses.
    TetMesh t{{{0, 0, 0}, {1, 0, 0}, {0.5, 1e-11, 0}, {0, 0, 1}}, {{0, 1, 2, 3}}};
    CHECK_THAT(tet_error(t), Catch::Contains("boundary has 1 near-zero-area triangle"));
    t.nodes[2][1] = 1e-3;
    CHECK(tet_error(t) == "(valid)");
  }
  SECTION("A node used by no tet is reported.") {
    m.nodes.push_back({5, 5, 5});
    CHECK_THAT(tet_error(m), Catch::Contains("1 node is used by no tet, first is node 27"));
  }
  SECTION("A face shared by three tets is non-manifold.") {
    // A copy of tet 0: its interior faces are now shared by three tets.
    m.tets.push_back(m.tets[0]);
    CHECK_THAT(tet_error(m), Catch::Contains("shared by more than two tets (non-manifold)"));
  }
  SECTION("Two tets sharing only an edge give a non-manifold edge.") {
    const TetMesh two{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}, {0, 0, -1}},
                      {{0, 1, 2, 3}, {0, 1, 4, 5}}};
    CHECK_THAT(tet_error(two),
               Catch::Contains("surface has 1 non-manifold edge (shared by more than two "
                               "triangles), first between vertices 0 and 1"));
  }
  SECTION("Two tets sharing only a vertex give a non-manifold vertex.") {
    const TetMesh two{
        {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
        {{0, 1, 2, 3}, {0, 4, 6, 5}}};
    CHECK_THAT(tet_error(two),
               Catch::Contains("surface has 1 non-manifold vertex (several fans of triangles meet "
                               "there), first is vertex 0"));
  }
  SECTION("Two separate blocks are two components, which is valid.") {
    const TetMesh other = tetseg::test::kuhn_grid(1, 1, 1, [](int i, int j, int k) {
      return Vec3{double(i) + 5.0, double(j), double(k)};
    });
    CHECK(tet_error(join(m, other)) == "(valid)");
  }
  SECTION("A block inside another block's volume overlaps it at rest.") {
    const TetMesh big = tetseg::test::kuhn_grid(3, 3, 3, [](int i, int j, int k) {
      return Vec3{2.0 * i, 2.0 * j, 2.0 * k};
    });
    const TetMesh small = tetseg::test::kuhn_grid(1, 1, 1, [](int i, int j, int k) {
      return Vec3{2.5 + i, 2.5 + j, 2.5 + k};
    });
    CHECK_THAT(tet_error(join(big, small)),
               Catch::Contains("component 2 (node 68) lies inside component 1 of 2: their "
                               "volumes overlap at rest"));
  }
  SECTION("A hollow block (a cavity) is refused.") {
    // 3^3 cubes without the middle one: one component bounded by two closed surfaces.
    TetMesh hollow = block(3);
    hollow.tets.erase(hollow.tets.begin() + 6 * 13, hollow.tets.begin() + 6 * 14);
    CHECK_THAT(tet_error(hollow),
               Catch::Contains("component 1 of 1 (node 0) is bounded by 2 closed surfaces: "
                               "bodies with a cavity are not supported"));
  }
  SECTION("A bar coiled past a full turn intersects itself at rest.") {
    // 12 cubes around 1.25 turns of a circle of radius 3 in the xz plane: both ends overlap.
    const double kPi = std::acos(-1.0);
    const TetMesh coil = tetseg::test::kuhn_grid(12, 1, 1, [&](int i, int j, int k) {
      const double angle = 2.5 * kPi * i / 12.0;
      const double r = 3.0 + k;
      return Vec3{r * std::cos(angle), double(j) + 0.1 * angle, r * std::sin(angle)};
    });
    CHECK_THAT(tet_error(coil), Catch::Contains("surface self-intersects ("));
    CHECK_THAT(tet_error(coil), Catch::Contains("pairs of triangles"));
  }
  SECTION("A surface with a missing triangle is open; the border edges are counted.") {
    Surface s = extract_surface(m);
    s.triangles.pop_back();
    try {
      validate_tet_mesh(m, s, "m.mesh");
      FAIL("accepted an open surface");
    } catch (const InputError& e) {
      CHECK_THAT(e.what(), Catch::Contains("surface is not closed (3 border edges"));
    }
  }
}

TEST_CASE("Each closed-surface defect is reported with a clear message", "[validate]") {
  TriangleMesh s = block_surface(2);
  SECTION("Removing two adjacent triangles leaves 4 border edges.") {
    // Remove a triangle and one neighbour that shares an edge with it.
    const Tri first = s.triangles.front();
    std::size_t neighbour = 0;
    for (std::size_t t = 1; t < s.triangles.size() && neighbour == 0; ++t) {
      int shared = 0;
      for (auto a : first)
        for (auto b : s.triangles[t]) shared += a == b;
      if (shared == 2) neighbour = t;
    }
    REQUIRE(neighbour != 0);
    s.triangles.erase(s.triangles.begin() + static_cast<std::ptrdiff_t>(neighbour));
    s.triangles.erase(s.triangles.begin());
    CHECK_THAT(surface_error(s), Catch::Contains("surface is not closed (4 border edges"));
  }
  SECTION("A zero-area triangle is reported.") {
    s.vertices.push_back(s.vertices[s.triangles[0][0]]);
    s.triangles[0][1] = static_cast<std::uint32_t>(s.vertices.size() - 1);
    CHECK_THAT(surface_error(s), Catch::Contains("1 zero-area triangle, first is triangle 0"));
  }
  SECTION("A flipped triangle makes the orientation inconsistent.") {
    std::swap(s.triangles[3][0], s.triangles[3][1]);
    CHECK_THAT(surface_error(s), Catch::Contains("surface is not consistently oriented (3 edges"));
  }
  SECTION("A doubled triangle gives non-manifold edges.") {
    s.triangles.push_back(s.triangles[0]);
    CHECK_THAT(surface_error(s), Catch::Contains("non-manifold edges"));
  }
  SECTION("Two copies are two components.") {
    TriangleMesh two = s;
    const auto offset = static_cast<std::uint32_t>(s.vertices.size());
    for (Vec3 p : s.vertices) two.vertices.push_back({p[0] + 10, p[1], p[2]});
    for (Tri t : s.triangles)
      two.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
    CHECK_THAT(surface_error(two), Catch::Contains("surface has 2 connected components"));
  }
  SECTION("Pushing one corner through the block makes the surface self-intersect.") {
    // Push the corner (2, 2, 2) through the block to (-1, -1, -1).
    for (Vec3& p : s.vertices)
      if (p == Vec3{2, 2, 2}) p = {-1, -1, -1};
    CHECK_THAT(surface_error(s), Catch::Contains("surface self-intersects"));
  }
  SECTION("Two cubes sharing a corner give a non-manifold vertex.") {
    TriangleMesh two = s;
    const auto offset = static_cast<std::uint32_t>(s.vertices.size());
    for (Vec3 p : s.vertices) two.vertices.push_back({p[0] + 2, p[1] + 2, p[2] + 2});
    // Corner (2,2,2) of the first equals corner (0,0,0) + 2 of the second: weld them.
    std::uint32_t corner_a = 0;
    std::uint32_t corner_b = 0;
    for (std::uint32_t v = 0; v < offset; ++v) {
      if (s.vertices[v] == Vec3{2, 2, 2}) corner_a = v;
      if (s.vertices[v] == Vec3{0, 0, 0}) corner_b = v + offset;
    }
    for (Tri t : s.triangles) {
      Tri u{t[0] + offset, t[1] + offset, t[2] + offset};
      for (auto& v : u)
        if (v == corner_b) v = corner_a;
      two.triangles.push_back(u);
    }
    two.vertices[corner_b] = {100, 100, 100};  // unused; not on any triangle
    CHECK_THAT(surface_error(two),
               Catch::Contains("surface has 1 non-manifold vertex (several fans of triangles meet "
                               "there), first is vertex " +
                               std::to_string(corner_a)));
  }
}
