// `--repair fix` (MeshingOptions::Repair::kFix) and `--repair wrap` (kWrap): each repair on a
// small generated defect, checked against the same input with repairs off, the result validated
// (closed, 2-manifold, no self-intersection) and its volume compared with the exact one.

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "../../preprocess/src/repair_internal.hpp"
#include "preprocess/support/mesh_measures.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tetseg/testing/charge_shapes.hpp"
#include "tetseg/testing/test_data.hpp"

using namespace tetseg::preprocess;

namespace {

/// The unit cube: 8 corners, 12 outward triangles.
TriangleMesh cube() {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return m;
}

MeshingOptions coarse(MeshingOptions::Repair repair) {
  MeshingOptions m;
  m.facet_size = 0.25;
  m.optimize = false;
  m.repair = repair;
  return m;
}

std::size_t count_of(const TetrahedralizeNotes& notes, const std::string& kind) {
  for (const RepairCount& r : notes.repairs)
    if (r.kind.find(kind) != std::string::npos) return r.count;
  return 0;
}

/// Meshes `s` with repairs on (must succeed, valid, volume 1) and off (must fail with
/// `unrepaired_error`); returns the repairs. `holed`: the input lacks part of the cube, so
/// the mesh-to-input distance is not checked here.
TetrahedralizeNotes fixed_and_refused(const TriangleMesh& s, const std::string& unrepaired_error,
                                      bool holed = false) {
  try {
    tetrahedralize(s, coarse(MeshingOptions::Repair::kNone), "defect.off");
    FAIL("the defect was meshed without repair");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains(unrepaired_error));
  }
  TetrahedralizeNotes notes;
  const TetMesh m = tetrahedralize(s, coarse(MeshingOptions::Repair::kFix), "defect.off", &notes);
  validate_tet_mesh(m, extract_surface(m), "repaired");
  CHECK(total_tet_volume(m) == Approx(1.0).epsilon(0.02));
  // The repairs kept the shape: what is left is Mesh_3's rounding of the cube's corners and
  // edges (no feature protection; facet distance 0.025, here about 0.035 of the diagonal).
  CHECK(notes.hausdorff_input_to_mesh >= 0.0);
  CHECK(notes.hausdorff_input_to_mesh < 0.05);
  if (!holed) CHECK(notes.hausdorff_mesh_to_input < 0.05);
  return notes;
}

/// An open tube about z: radius 0.5, z in [0, 2], `segments` around, no caps.
TriangleMesh open_cylinder(std::uint32_t segments) {
  TriangleMesh m;
  const double pi = std::acos(-1.0);
  for (int ring = 0; ring <= 4; ++ring)
    for (std::uint32_t i = 0; i < segments; ++i) {
      const double a = 2.0 * pi * i / segments;
      m.vertices.push_back({0.5 * std::cos(a), 0.5 * std::sin(a), 0.5 * ring});
    }
  for (std::uint32_t ring = 0; ring < 4; ++ring)
    for (std::uint32_t i = 0; i < segments; ++i) {
      const std::uint32_t a = ring * segments + i;
      const std::uint32_t b = ring * segments + (i + 1) % segments;
      m.triangles.push_back({a, b, b + segments});
      m.triangles.push_back({a, b + segments, a + segments});
    }
  return m;
}

/// Meshes `s` wrapped (alpha `alpha` of the diagonal); the result must be valid.
TetMesh wrapped(const TriangleMesh& s, double alpha, TetrahedralizeNotes& notes) {
  MeshingOptions m = coarse(MeshingOptions::Repair::kWrap);
  m.facet_size = 0.15;
  m.wrap_alpha = alpha;
  const TetMesh mesh = tetrahedralize(s, m, "defect.off", &notes);
  validate_tet_mesh(mesh, extract_surface(mesh), "wrapped");
  REQUIRE(notes.repairs.size() == 1);
  CHECK(notes.repairs[0].kind.find("alpha wrap") != std::string::npos);
  CHECK(notes.repairs[0].count > 0);
  return mesh;
}

/// `s` is refused by `--repair fix`: the error names a self-intersection and points to wrap.
void refused_by_fix_as_self_intersecting(const TriangleMesh& s) {
  try {
    tetrahedralize(s, coarse(MeshingOptions::Repair::kFix), "defect.off");
    FAIL("a self-intersecting surface was meshed by fix");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("surface self-intersects"));
    CHECK_THAT(e.what(), Catch::Contains("--repair wrap"));
  }
}

}  // namespace

TEST_CASE("Shape-keeping repairs fix small defects and say what they did", "[meshing][repair]") {
  SECTION("A valid cube needs no repair.") {
    TetrahedralizeNotes notes;
    tetrahedralize(cube(), coarse(MeshingOptions::Repair::kFix), "cube.off", &notes);
    CHECK(notes.repairs.empty());
  }
  SECTION("Three flipped triangles are flipped back.") {
    TriangleMesh s = cube();
    for (std::size_t t : {0u, 5u, 9u}) std::swap(s.triangles[t][1], s.triangles[t][2]);
    const TetrahedralizeNotes notes = fixed_and_refused(s, "not consistently oriented");
    // orient_polygon_soup may flip either side of the seam; three or nine flips agree.
    const std::size_t flipped = count_of(notes, "flipped");
    CHECK((flipped == 3 || flipped == 9));
  }
  SECTION("Duplicate triangles, in either orientation, are merged.") {
    TriangleMesh s = cube();
    s.triangles.push_back(s.triangles[4]);
    s.triangles.push_back({s.triangles[7][0], s.triangles[7][2], s.triangles[7][1]});
    const TetrahedralizeNotes notes = fixed_and_refused(s, "non-manifold edge");
    CHECK(count_of(notes, "duplicate triangles removed") == 2);
  }
  SECTION("A triangle with a repeated corner and an unused vertex are removed.") {
    TriangleMesh s = cube();
    s.triangles.push_back({1, 1, 6});
    s.vertices.push_back({5, 5, 5});
    const TetrahedralizeNotes notes = fixed_and_refused(s, "zero-area triangle");
    CHECK(count_of(notes, "repeated corner") == 1);
    CHECK(count_of(notes, "isolated vertices removed") == 1);
  }
  SECTION("Two halves of the cube whose seam vertices are duplicated are stitched.") {
    // Bottom, top and front (triangles 0-5) keep vertices 0-7; right, back and left (6-11)
    // use copies 8-15 at the same places, so the seam's edges are border edges twice over.
    TriangleMesh s = cube();
    for (std::size_t v = 0; v < 8; ++v) s.vertices.push_back(s.vertices[v]);
    for (std::size_t t = 6; t < 12; ++t)
      for (std::uint32_t& v : s.triangles[t]) v += 8;
    // The independent count: edges of the closed cube with one triangle in each half.
    std::size_t seam = 0;
    const TriangleMesh whole = cube();
    for (std::size_t t = 0; t < 6; ++t)
      for (std::size_t u = 6; u < 12; ++u) {
        std::size_t shared = 0;
        for (std::uint32_t a : whole.triangles[t])
          for (std::uint32_t b : whole.triangles[u]) shared += a == b;
        seam += shared == 2;
      }
    REQUIRE(seam > 0);
    const TetrahedralizeNotes notes = fixed_and_refused(s, "not closed");
    CHECK(count_of(notes, "border edges stitched") == seam);
    CHECK(count_of(notes, "holes filled") == 0);
  }
  SECTION("A zero-area triangle on an edge of the cube is removed.") {
    // The front's triangle (0 1 5) is split at the midpoint 8 of edge 0-1, and the sliver
    // (0 1 8), whose corners are collinear, closes the surface between it and the bottom.
    TriangleMesh s = cube();
    s.vertices.push_back({0.5, 0, 0});
    s.triangles[4] = {0, 8, 5};
    s.triangles.push_back({8, 1, 5});
    s.triangles.push_back({0, 1, 8});
    const TetrahedralizeNotes notes = fixed_and_refused(s, "zero-area triangle");
    CHECK(count_of(notes, "zero-area triangles removed") == 1);
  }
}

TEST_CASE("Fix removes a local self-intersection by CGAL's local remeshing", "[meshing][repair]") {
  // A geodesic sphere (720 triangles) with one vertex slid along the surface past its
  // neighbours: its fan folds over the next triangles, a few intersecting pairs in one place.
  TriangleMesh s = tetseg::test::icosphere(6);
  Vec3& p = s.vertices[0];
  const Vec3 tangent = {-p[1], p[0], 0.0};  // p is not on the z axis
  const double t = std::hypot(tangent[0], tangent[1]);
  Vec3 moved;
  for (int k = 0; k < 3; ++k) moved[k] = p[k] + 0.35 * tangent[k] / t;
  const double r = std::hypot(moved[0], moved[1], moved[2]);
  for (int k = 0; k < 3; ++k) p[k] = 1.02 * moved[k] / r;
  std::size_t pairs = 0;  // what validation of the unrepaired surface reports
  try {
    tetrahedralize(s, coarse(MeshingOptions::Repair::kNone), "folded.off");
    FAIL("the folded sphere was meshed without repair");
  } catch (const InputError& e) {
    const std::string message = e.what();
    const std::string prefix = "surface self-intersects (";
    REQUIRE(message.find(prefix) != std::string::npos);
    pairs = std::stoul(message.substr(message.find(prefix) + prefix.size()));
  }
  TetrahedralizeNotes notes;
  const TetMesh m = tetrahedralize(s, coarse(MeshingOptions::Repair::kFix), "folded.off", &notes);
  validate_tet_mesh(m, extract_surface(m), "repaired");
  const std::size_t removed = count_of(notes, "self-intersecting triangle pairs removed");
  CHECK(removed > 0);
  CHECK(removed == pairs);
  // The rest of the sphere is kept: the volume of the unit ball within Mesh_3's facet error.
  CHECK(total_tet_volume(m) == Approx(4.0 * std::acos(-1.0) / 3.0).epsilon(0.05));
  CHECK(notes.hausdorff_input_to_mesh < 0.1);
}

namespace {

/// `s` with the vertex nearest `direction` slid along the surface past its neighbours (about
/// 0.35 of the radius, then 1.02 out): its fan folds over the next triangles, a few intersecting
/// pairs in one place. `direction` must not be along z.
void fold_near(TriangleMesh& s, const Vec3& direction) {
  std::size_t nearest = 0;
  double best = -1e300;
  for (std::size_t v = 0; v < s.vertices.size(); ++v) {
    const Vec3& q = s.vertices[v];
    const double along = q[0] * direction[0] + q[1] * direction[1] + q[2] * direction[2];
    if (along > best) best = along, nearest = v;
  }
  Vec3& p = s.vertices[nearest];
  const Vec3 tangent = {-p[1], p[0], 0.0};
  const double t = std::hypot(tangent[0], tangent[1]);
  Vec3 moved;
  for (int k = 0; k < 3; ++k) moved[k] = p[k] + 0.35 * tangent[k] / t;
  const double r = std::hypot(moved[0], moved[1], moved[2]);
  for (int k = 0; k < 3; ++k) p[k] = 1.02 * moved[k] / r;
}

}  // namespace

TEST_CASE("Self-intersection removal is bounded by work, not time: the same repair every run",
          "[meshing][repair]") {
  // Three folds far apart on a geodesic sphere: three separate patches of intersecting
  // triangles, so at least three local remeshings (one per patch).
  TriangleMesh s = tetseg::test::icosphere(6);
  fold_near(s, {1.0, 0.3, 0.2});
  fold_near(s, {-1.0, 0.2, -0.3});
  fold_near(s, {0.2, -1.0, 0.4});
  const auto removed = [](const std::vector<RepairCount>& repairs) {
    for (const RepairCount& r : repairs)
      if (r.kind.find("self-intersecting triangle pairs removed") != std::string::npos)
        return r.count;
    return std::size_t{0};
  };
  TriangleMesh once = s, twice = s;
  const auto first = tetseg::preprocess::detail::repair_soup(once);
  const auto second = tetseg::preprocess::detail::repair_soup(twice);
  REQUIRE(removed(first) > 0);
  CHECK(removed(second) == removed(first));
  CHECK(once.vertices == twice.vertices);
  CHECK(once.triangles == twice.triangles);
  // The bound takes effect: allowed two local remeshings, the removal stops before the third
  // patch and nothing is kept (the surface is returned as it was, pairs left to validation).
  TriangleMesh bounded = s;
  const auto stopped = tetseg::preprocess::detail::repair_soup(bounded, false, nullptr, 2);
  CHECK(removed(stopped) == 0);
  CHECK(bounded.triangles.size() == s.triangles.size());
  // The build's --time-limit (the watchdog's flag, raised) stops it too.
  const std::atomic<bool> time_limit_reached{true};
  TriangleMesh late = s;
  CHECK(removed(tetseg::preprocess::detail::repair_soup(
            late, false, nullptr, tetseg::preprocess::detail::kMaxRemovalPatches,
            &time_limit_reached)) == 0);
}

TEST_CASE("Fix tries at most 4000 border edges of holes over 64 edges", "[meshing][repair]") {
  // Ten open tubes, each with two round holes of 201 border edges: 4020 edges over 64 in all.
  // Each hole fills flat (no fold, a disk's area, no crossing), but the work bound stops before
  // the twentieth (19 x 201 = 3819 tried; the twentieth would make 4020).
  TriangleMesh tubes;
  for (int k = 0; k < 10; ++k) {
    const TriangleMesh tube = open_cylinder(201);
    const auto offset = static_cast<std::uint32_t>(tubes.vertices.size());
    for (Vec3 p : tube.vertices) {
      p[0] += 2.0 * k;
      tubes.vertices.push_back(p);
    }
    for (const Tri& t : tube.triangles)
      tubes.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  }
  const auto repairs = tetseg::preprocess::detail::repair_soup(tubes);
  std::size_t filled = 0;
  for (const RepairCount& r : repairs)
    if (r.kind == "holes filled") filled = r.count;
  CHECK(filled == 19);
}

namespace {

/// The part of an 11.5k-triangle unit sphere at z >= `z_cut` (its triangles with every
/// corner there): an open dome, one hole of about 100 border edges around its rim.
TriangleMesh dome(double z_cut) {
  TriangleMesh s = tetseg::test::icosphere(24);
  std::vector<Tri> kept;
  for (const Tri& t : s.triangles)
    if (s.vertices[t[0]][2] >= z_cut && s.vertices[t[1]][2] >= z_cut &&
        s.vertices[t[2]][2] >= z_cut)
      kept.push_back(t);
  s.triangles = kept;
  return s;
}

std::size_t holes_filled(TriangleMesh s) {
  for (const RepairCount& r : tetseg::preprocess::detail::repair_soup(s))
    if (r.kind == "holes filled") return r.count;
  return 0;
}

}  // namespace

TEST_CASE("Fix leaves open a hole over 64 edges whose patch folds against its rim",
          "[meshing][repair]") {
  // A dome's rim at height z meets the patch across it at 90 + asin(z) degrees: 107 at z = 0.3,
  // filled; 134 at z = 0.7, over the 120-degree fold limit, so left open (nothing else refuses
  // that patch: it neither bulges nor crosses the dome).
  CHECK(holes_filled(dome(0.3)) == 1);
  CHECK(holes_filled(dome(0.7)) == 0);
}

TEST_CASE("Fix leaves open a hole over 64 edges whose patch crosses the surface",
          "[meshing][repair]") {
  // An open tube (two round holes of 201 border edges at z = 0 and z = 2) and a small closed
  // sphere sitting across the plane of its upper end: that end's flat patch would cut through
  // the sphere, so only the lower hole is filled (no fold, a disk's area: only the crossing
  // refuses it).
  TriangleMesh s = open_cylinder(201);
  const TriangleMesh ball = tetseg::test::icosphere(2, 0.2);
  const auto offset = static_cast<std::uint32_t>(s.vertices.size());
  for (Vec3 p : ball.vertices) {
    p[2] += 2.0;
    s.vertices.push_back(p);
  }
  for (const Tri& t : ball.triangles)
    s.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  CHECK(holes_filled(open_cylinder(201)) == 2);
  CHECK(holes_filled(s) == 1);
}

TEST_CASE("Fix fills small holes, names what it cannot repair and points to wrap",
          "[meshing][repair]") {
  SECTION("A cube with a triangle missing is closed again.") {
    TriangleMesh s = cube();
    s.triangles.erase(s.triangles.begin());  // a hole: three border edges
    const TetrahedralizeNotes notes = fixed_and_refused(s, "not closed (3 border edges", true);
    CHECK(count_of(notes, "holes filled") == 1);
    // The patch is farthest from the input at the missing triangle's incentre (see below).
    CHECK(notes.hausdorff_mesh_to_input ==
          Approx((2.0 - std::sqrt(2.0)) / 2.0 / std::sqrt(3.0)).margin(0.015));
  }
  SECTION("Two holes of 1001 border edges, over the limit of 1000, are left and named.") {
    try {
      tetrahedralize(open_cylinder(1001), coarse(MeshingOptions::Repair::kFix), "tube.off");
      FAIL("an open tube was meshed by fix");
    } catch (const InputError& e) {
      CHECK_THAT(e.what(),
                 Catch::Contains("not closed (2002 border edges, first between vertices"));
      CHECK_THAT(e.what(), Catch::Contains("--repair wrap"));
      CHECK(e.file() == "tube.off");
    }
  }
}

TEST_CASE("Fix fills a hole over 64 border edges near the shape it cuts", "[meshing][repair]") {
  // The cap z > 0.6 of an 11.5k-triangle unit sphere removed: a hole of about 110 border
  // edges whose rim reaches z_top = 0.64 (triangles below 0.6 kept whole). The faired patch
  // follows the sphere: the ball's volume 4 pi / 3 within Mesh_3's error (2 % at this size),
  // where a flat patch would lack the cap, pi 0.4^2 (3 - 0.4) / 3 = 0.44 (10 % of the ball);
  // its farthest point from the input, the pole, lies sqrt(2 - 2 z_top) from the top of the
  // rim (0.245 of the diagonal), where a flat patch's centre lies the rim's radius
  // sqrt(1 - z_top^2) from it (0.222).
  TriangleMesh s = tetseg::test::icosphere(24);
  std::vector<Tri> kept;
  double z_top = 0.0;
  for (const Tri& t : s.triangles)
    if (s.vertices[t[0]][2] <= 0.6 || s.vertices[t[1]][2] <= 0.6 || s.vertices[t[2]][2] <= 0.6) {
      kept.push_back(t);
      for (const std::uint32_t v : t) z_top = std::max(z_top, s.vertices[v][2]);
    }
  s.triangles = kept;
  const double diagonal = 2.0 * std::sqrt(3.0);
  REQUIRE(std::sqrt(2.0 - 2.0 * z_top) - std::sqrt(1.0 - z_top * z_top) > 0.05);
  MeshingOptions m = coarse(MeshingOptions::Repair::kFix);
  m.facet_size = 0.1;
  TetrahedralizeNotes notes;
  const TetMesh mesh = tetrahedralize(s, m, "capless.off", &notes);
  validate_tet_mesh(mesh, extract_surface(mesh), "capless");
  CHECK(count_of(notes, "holes filled") == 1);
  CHECK(total_tet_volume(mesh) == Approx(4.0 * std::acos(-1.0) / 3.0).epsilon(0.04));
  // Faired up towards the pole (to z ~ 0.9 at these sizes), above where a flat patch lies.
  CHECK(notes.hausdorff_mesh_to_input > std::sqrt(1.0 - z_top * z_top) / diagonal + 0.005);
  CHECK(notes.hausdorff_mesh_to_input < std::sqrt(2.0 - 2.0 * z_top) / diagonal + 0.005);
  CHECK(notes.hausdorff_input_to_mesh < 0.01);
}

TEST_CASE("Fix leaves open a large hole whose patch would fold and cross the surface",
          "[meshing][repair][cgal-data]") {
  // libcgal-demo elephant-with-holes.off: all holes but one under 64 border edges; the
  // 78-edge one is a long slit whose faired patch turns back onto the surface (a fold of more
  // than 120 degrees against a neighbour) and crosses it, so it stays open and is named
  // (either rule alone refuses it; without both the patch is kept and leaves a zero-area
  // triangle).
  const std::string path = std::string(TETSEG_CGAL_MESH_DIR) + "/elephant-with-holes.off";
  if (!tetseg::test::have_test_data(path, "CGAL demo mesh elephant-with-holes.off")) return;
  try {
    tetrahedralize(read_triangle_mesh(path), coarse(MeshingOptions::Repair::kFix),
                   "elephant-with-holes.off");
    FAIL("the folding patch was kept");
  } catch (const InputError& e) {
    CHECK_THAT(e.what(), Catch::Contains("surface is not closed (78 border edges"));
  }
}

TEST_CASE("Wrap closes holes, open surfaces and self-intersections", "[meshing][repair][wrap]") {
  TetrahedralizeNotes notes;
  SECTION("A cube with a triangle missing: an alpha larger than the hole closes it.") {
    TriangleMesh s = cube();
    s.triangles.erase(s.triangles.begin());
    const TetMesh m = wrapped(s, 0.5, notes);
    // The wrap lies just outside the input (offset 0.002 of the diagonal).
    CHECK(total_tet_volume(m) == Approx(1.0).epsilon(0.05));
    CHECK(notes.hausdorff_input_to_mesh < 0.05);
    // The patch over the hole is farthest from the input at the incentre of the missing
    // right triangle (legs 1): the inradius (2 - sqrt 2) / 2 over the diagonal sqrt 3.
    CHECK(notes.hausdorff_mesh_to_input ==
          Approx((2.0 - std::sqrt(2.0)) / 2.0 / std::sqrt(3.0)).margin(0.015));
  }
  SECTION("An open cylinder: wrapped into a capped one.") {
    const TetMesh m = wrapped(open_cylinder(48), 0.3, notes);
    const double pi = std::acos(-1.0);
    const double prism = 48 * 0.5 * 0.25 * std::sin(2 * pi / 48) * 2.0;  // the 48-gon prism
    CHECK(total_tet_volume(m) == Approx(prism).epsilon(0.06));
  }
  SECTION("Two cubes sharing a corner (a non-manifold vertex): fix refuses, wrap joins them.") {
    TriangleMesh s = cube();
    const TriangleMesh other = cube();
    for (std::size_t i = 1; i < other.vertices.size(); ++i) {
      const Vec3& p = other.vertices[i];
      s.vertices.push_back({p[0] + 1.0, p[1] + 1.0, p[2] + 1.0});
    }
    // The second cube's corner 0 is the first cube's corner 6, (1, 1, 1).
    const auto shifted = [](std::uint32_t v) { return v == 0 ? 6u : v + 7u; };
    for (const Tri& t : other.triangles)
      s.triangles.push_back({shifted(t[0]), shifted(t[1]), shifted(t[2])});
    // Duplicating the vertex leaves two cubes touching at a point: not an embedded surface.
    refused_by_fix_as_self_intersecting(s);
    const TetMesh m = wrapped(s, 0.03, notes);
    // Two unit cubes; the wrap's bridge at the corner and its offset add little.
    CHECK(total_tet_volume(m) == Approx(2.0).epsilon(0.05));
    CHECK(notes.hausdorff_mesh_to_input < 0.05);
  }
  SECTION("Two interpenetrating spheres: fix refuses, wrap makes their union.") {
    TriangleMesh s = tetseg::test::icosphere(6);
    const TriangleMesh other = tetseg::test::icosphere(6);
    const std::uint32_t base = static_cast<std::uint32_t>(s.vertices.size());
    for (Vec3 p : other.vertices) s.vertices.push_back({p[0] + 1.0, p[1], p[2]});
    for (const Tri& t : other.triangles)
      s.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    refused_by_fix_as_self_intersecting(s);
    const TetMesh m = wrapped(s, 0.02, notes);
    // Union of two unit balls 1 apart: 2 (4/3 pi) - pi (4 + 1)(2 - 1)^2 / 12.
    const double pi = std::acos(-1.0);
    const double exact = 8.0 * pi / 3.0 - 5.0 * pi / 12.0;
    CHECK(total_tet_volume(m) == Approx(exact).epsilon(0.05));
    // The input inside the union is farthest from the wrap at each sphere's centre, which
    // lies on the other sphere: distance 1, over the diagonal sqrt(3^2 + 2^2 + 2^2).
    CHECK(notes.hausdorff_input_to_mesh == Approx(1.0 / std::sqrt(17.0)).margin(0.01));
    CHECK(notes.hausdorff_mesh_to_input < 0.02);
  }
}

TEST_CASE("Keeping the largest component drops floating debris and keeps the largest part",
          "[meshing][repair]") {
  // A small cube (side 0.2) listed first, then the unit cube 2 units away: the kept component
  // must be the unit cube by area, not the first one.
  TriangleMesh s;
  const TriangleMesh unit = cube();
  for (const Vec3& p : unit.vertices)
    s.vertices.push_back({0.2 * p[0] - 3.0, 0.2 * p[1], 0.2 * p[2]});
  s.triangles = unit.triangles;
  const std::uint32_t base = static_cast<std::uint32_t>(s.vertices.size());
  for (const Vec3& p : unit.vertices) s.vertices.push_back(p);
  for (const Tri& t : unit.triangles)
    s.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  MeshingOptions options = coarse(MeshingOptions::Repair::kFix);
  options.keep_largest_component = true;
  TetrahedralizeNotes notes;
  const TetMesh m = tetrahedralize(s, options, "debris.off", &notes);
  validate_tet_mesh(m, extract_surface(m), "kept");
  CHECK(count_of(notes, "smaller components removed") == 1);
  CHECK(total_tet_volume(m) == Approx(1.0).epsilon(0.02));
  for (const Vec3& p : m.nodes) CHECK(p[0] > -0.1);  // nothing of the debris is left
}

namespace {

/// Wraps and meshes `s` at default sizes (no optimisation, for speed); the result must pass
/// the tet-mesh validation (closed, 2-manifold boundary, no self-intersection, ...).
TetMesh wrapped_at_default_sizes(const TriangleMesh& s, TetrahedralizeNotes& notes,
                                 double max_deviation = MeshingOptions{}.max_deviation) {
  MeshingOptions m;
  m.optimize = false;
  m.repair = MeshingOptions::Repair::kWrap;
  m.max_deviation = max_deviation;
  const TetMesh mesh = tetrahedralize(s, m, "sheet.off", &notes);
  validate_tet_mesh(mesh, extract_surface(mesh), "wrapped");
  return mesh;
}

/// An n x n grid of squares over [0, 1]^2, two triangles each, at height height(x).
template <typename Height>
TriangleMesh grid_sheet(std::uint32_t n, Height height) {
  TriangleMesh m;
  for (std::uint32_t j = 0; j <= n; ++j)
    for (std::uint32_t i = 0; i <= n; ++i) {
      const double x = static_cast<double>(i) / n;
      m.vertices.push_back({x, static_cast<double>(j) / n, height(x)});
    }
  for (std::uint32_t j = 0; j < n; ++j)
    for (std::uint32_t i = 0; i < n; ++i) {
      const std::uint32_t a = j * (n + 1) + i;
      m.triangles.push_back({a, a + 1, a + n + 2});
      m.triangles.push_back({a, a + n + 2, a + n + 1});
    }
  return m;
}

using tetseg::test::diagonal_of;

/// The checks of a sheet meshed as a slab: the repairs say so (slab 0.02 of the diagonal
/// thick, 200 ten-thousandths), the volume is the sheet's area times that thickness (plus the
/// rounded rim: perimeter x pi r^2 / 2, r the offset), and the surface lies about the offset
/// (0.01 of the diagonal) from the sheet, plus Mesh_3's facet distance (1/400).
void check_slab(const TetMesh& m, const TetrahedralizeNotes& notes, double area, double perimeter,
                double diagonal) {
  REQUIRE(notes.repairs.size() == 2);
  CHECK(notes.repairs[0].kind == "surface replaced by an alpha wrap of this many triangles");
  CHECK(notes.repairs[0].count > 0);
  CHECK(notes.repairs[1].kind ==
        "surface wrapped as a slab this many ten thousandths of the diagonal thick");
  CHECK(notes.repairs[1].count == 200);
  const double pi = std::acos(-1.0);
  const double r = 0.01 * diagonal;
  CHECK(total_tet_volume(m) == Approx(area * 2.0 * r + perimeter * pi * r * r / 2.0).epsilon(0.15));
  CHECK(notes.hausdorff_input_to_mesh == Approx(0.01).margin(0.004));
  CHECK(notes.hausdorff_mesh_to_input == Approx(0.01).margin(0.004));
}

}  // namespace

TEST_CASE("Wrap meshes a sheet that encloses no volume as a slab, and says so",
          "[meshing][repair][wrap]") {
  TetrahedralizeNotes notes;
  SECTION("A flat square of two triangles.") {
    const TriangleMesh s = grid_sheet(1, [](double) { return 0.0; });
    const TetMesh m = wrapped_at_default_sizes(s, notes);
    check_slab(m, notes, 1.0, 4.0, std::sqrt(2.0));
  }
  SECTION("A curved open sheet (a shallow trough, 0.03 deep).") {
    const auto height = [](double x) { return 0.12 * (x - 0.5) * (x - 0.5); };
    const TriangleMesh s = grid_sheet(12, height);
    // The trough's area: its profile's length (the sum of the grid's chords) x 1.
    double profile = 0.0;
    for (int i = 0; i < 12; ++i)
      profile += std::hypot(1.0 / 12, height((i + 1) / 12.0) - height(i / 12.0));
    const TetMesh m = wrapped_at_default_sizes(s, notes);
    check_slab(m, notes, profile, 2.0 * (1.0 + profile), diagonal_of(s));
  }
}

TEST_CASE("Wrap builds a cube without one face, without meshing its thin wraps",
          "[meshing][repair][wrap]") {
  // The wrap at alpha 0.02 goes in through the missing face and wraps the walls on both
  // sides; so does the wrap at 0.16 in part (libcgal-demo cube-ouvert.off, on which Mesh_3
  // does not end). Those are not meshed.
  TriangleMesh s = cube();
  s.triangles.erase(s.triangles.begin() + 2, s.triangles.begin() + 4);  // the top face, z = 1
  TetrahedralizeNotes notes;
  SECTION("Within the default --max-deviation 0.01: a slab, not a lid across the box") {
    // Doubling alpha to 0.04 would pass 2 x 0.01: the open box becomes a slab 0.02 of the
    // diagonal thick (its five walls, area 5, times the thickness 0.02 sqrt 3, plus the rims
    // and corners). Its walls lie the offset 0.01 from the input; at the rim and the corners,
    // where the alpha ball (0.02) does not reach in, the slab's surface lies up to about
    // offset + alpha from it.
    const TetMesh m = wrapped_at_default_sizes(s, notes);
    CHECK(count_of(notes, "alpha doublings") == 0);
    CHECK(count_of(notes, "wrapped as a slab") == 200);
    CHECK(total_tet_volume(m) == Approx(5.0 * 0.02 * std::sqrt(3.0)).epsilon(0.25));
    CHECK(notes.hausdorff_input_to_mesh == Approx(0.01).margin(0.005));
    CHECK(notes.hausdorff_mesh_to_input >= 0.008);
    CHECK(notes.hausdorff_mesh_to_input <= 0.03);
  }
  SECTION("With --max-deviation 1: alpha grows until the wrap closes the box") {
    const TetMesh m = wrapped_at_default_sizes(s, notes, 1.0);
    CHECK(count_of(notes, "alpha wrap") > 0);
    CHECK(count_of(notes, "slab") == 0);
    CHECK(count_of(notes, "alpha doublings") >= 3);  // 0.02 to 0.16 were thin
    CHECK(total_tet_volume(m) == Approx(1.0).epsilon(0.05));
    // The lid is farthest from the input at its centre: half a side, over the diagonal.
    CHECK(notes.hausdorff_mesh_to_input == Approx(0.5 / std::sqrt(3.0)).margin(0.02));
  }
}

namespace {

/// A torus about z: centre radius `major`, tube radius `minor`, n x m quads split in two.
TriangleMesh torus(double major, double minor, std::uint32_t n, std::uint32_t m, Vec3 shift) {
  TriangleMesh t;
  const double pi = std::acos(-1.0);
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = 0; j < m; ++j) {
      const double u = 2.0 * pi * i / n, v = 2.0 * pi * j / m;
      const double ring = major + minor * std::cos(v);
      t.vertices.push_back({shift[0] + ring * std::cos(u), shift[1] + ring * std::sin(u),
                            shift[2] + minor * std::sin(v)});
    }
  const auto id = [&](std::uint32_t i, std::uint32_t j) { return (i % n) * m + j % m; };
  for (std::uint32_t i = 0; i < n; ++i)
    for (std::uint32_t j = 0; j < m; ++j) {
      t.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      t.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return t;
}

/// `s` through --repair auto (facet size `facet`, no optimisation); the mesh must be valid.
TetrahedralizeNotes auto_repaired(const TriangleMesh& s, double facet,
                                  double max_deviation = MeshingOptions{}.max_deviation) {
  MeshingOptions m = coarse(MeshingOptions::Repair::kAuto);
  m.facet_size = facet;
  m.max_deviation = max_deviation;
  TetrahedralizeNotes notes;
  const TetMesh mesh = tetrahedralize(s, m, "auto.off", &notes);
  validate_tet_mesh(mesh, extract_surface(mesh), "auto");
  return notes;
}

}  // namespace

TEST_CASE("Auto is fix, and the wrap with the reason where fix leaves a defect",
          "[meshing][repair][auto]") {
  using Repair = MeshingOptions::Repair;
  CHECK(MeshingOptions{}.repair == Repair::kAuto);  // the default
  SECTION("A clean closed surface takes fix.") {
    const TetrahedralizeNotes notes = auto_repaired(cube(), 0.25);
    CHECK(notes.repair_used == Repair::kFix);
    CHECK(notes.fallback_reason.empty());
    CHECK(notes.repairs.empty());
  }
  SECTION("A small hole is filled by fix, no wrap.") {
    TriangleMesh s = cube();
    s.triangles.erase(s.triangles.begin());
    const TetrahedralizeNotes notes = auto_repaired(s, 0.25);
    CHECK(notes.repair_used == Repair::kFix);
    CHECK(count_of(notes, "holes filled") == 1);
  }
  SECTION("A sphere with a large hole: fix fills it, auto checks the patch's deviation") {
    // The cap z > 0.6 of an 11.5k-triangle unit sphere removed: a hole of about 110 border edges
    // (radius 0.8), a fifth of the area once filled: fix's faired patch reaches the pole, 0.81
    // from the top of the rim (the test above), 0.23 of the diagonal 2 sqrt 3.
    TriangleMesh s = tetseg::test::icosphere(24);
    std::vector<Tri> kept;
    for (const Tri& t : s.triangles)
      if (s.vertices[t[0]][2] <= 0.6 || s.vertices[t[1]][2] <= 0.6 || s.vertices[t[2]][2] <= 0.6)
        kept.push_back(t);
    s.triangles = kept;
    SECTION("Over the default --max-deviation 0.01: the open sphere as a slab, with the reason") {
      // The slab's faces lie the sheet offset, 0.01 of the diagonal, from the input.
      const TetrahedralizeNotes notes = auto_repaired(s, 0.2);
      CHECK(notes.repair_used == Repair::kWrap);
      CHECK_THAT(notes.fallback_reason, Catch::Contains("the holes filled by fix ("));
      CHECK_THAT(notes.fallback_reason, Catch::Contains("over --max-deviation 0.01"));
      CHECK(count_of(notes, "wrapped as a slab") == 200);
      CHECK(notes.hausdorff_input_to_mesh == Approx(0.01).margin(0.006));
      CHECK(notes.hausdorff_mesh_to_input == Approx(0.01).margin(0.006));
    }
    SECTION("Within --max-deviation 0.5: fix's filled sphere") {
      const TetrahedralizeNotes notes = auto_repaired(s, 0.2, 0.5);
      CHECK(notes.repair_used == Repair::kFix);
      CHECK(notes.fallback_reason.empty());
      CHECK(count_of(notes, "holes filled") == 1);
      CHECK(notes.hausdorff_input_to_mesh < 0.02);
      CHECK(notes.hausdorff_mesh_to_input == Approx(0.82 / (2.0 * std::sqrt(3.0))).margin(0.01));
    }
  }
  SECTION("A hole fix fills but that makes a quarter of the surface is kept within the bound") {
    // The cap z > 0.5 of a 720-triangle unit sphere removed: one hole under the fill limit,
    // whose patch is about a quarter of the area (the cap's share of a sphere: (1 - 0.5) / 2).
    // The rim (the nearest input to the patch) lies between z = 0.5 and 0.7 (kept triangles
    // reach above 0.5), radius 0.71 to 0.87: a flat patch's centre is that radius from it,
    // 0.2 to 0.25 of the diagonal 2 sqrt 3; a patch faired up to the pole at most 1, 0.29.
    TriangleMesh s = tetseg::test::icosphere(6);
    std::vector<Tri> kept;
    for (const Tri& t : s.triangles)
      if (s.vertices[t[0]][2] <= 0.5 || s.vertices[t[1]][2] <= 0.5 || s.vertices[t[2]][2] <= 0.5)
        kept.push_back(t);
    s.triangles = kept;
    SECTION("Over the default --max-deviation: wrapped, as a slab, with the reason") {
      const TetrahedralizeNotes notes = auto_repaired(s, 0.2);
      CHECK(notes.repair_used == Repair::kWrap);
      CHECK_THAT(notes.fallback_reason, Catch::Contains("the holes filled by fix ("));
      CHECK_THAT(notes.fallback_reason, Catch::Contains("over --max-deviation 0.01"));
      CHECK(count_of(notes, "wrapped as a slab") == 200);
      CHECK(std::max(notes.hausdorff_input_to_mesh, notes.hausdorff_mesh_to_input) < 0.02);
    }
    SECTION("Fix's filled sphere after all when the wrap lies further from the input") {
      // A slab 0.4 of the diagonal off the input deviates more than the patch (under 0.31).
      MeshingOptions m = coarse(Repair::kAuto);
      m.facet_size = 0.2;
      m.wrap_sheet_offset = 0.4;
      TetrahedralizeNotes notes;
      const TetMesh mesh = tetrahedralize(s, m, "auto.off", &notes);
      validate_tet_mesh(mesh, extract_surface(mesh), "auto");
      CHECK(notes.repair_used == Repair::kFix);
      CHECK(notes.fallback_reason.empty());
      CHECK(count_of(notes, "holes filled") == 1);
      CHECK(count_of(notes, "slab") == 0);
      CHECK(notes.hausdorff_mesh_to_input < 0.31);
      CHECK(notes.deviation_excess > 0.19);
    }
    SECTION("Within --max-deviation 0.5: fix's filled sphere") {
      const TetrahedralizeNotes notes = auto_repaired(s, 0.2, 0.5);
      CHECK(notes.repair_used == Repair::kFix);
      CHECK(notes.fallback_reason.empty());
      CHECK(count_of(notes, "holes filled") == 1);
      CHECK(notes.hausdorff_input_to_mesh < 0.02);
      CHECK(notes.hausdorff_mesh_to_input > 0.2);
      CHECK(notes.hausdorff_mesh_to_input < 0.31);
    }
  }
  SECTION("Two interpenetrating tori (more crossing pairs than fix removes) are wrapped.") {
    TriangleMesh s = torus(1.0, 0.3, 64, 16, {0, 0, 0});
    const TriangleMesh other = torus(1.0, 0.3, 64, 16, {0.5, 0, 0});
    const std::uint32_t base = static_cast<std::uint32_t>(s.vertices.size());
    for (const Vec3& p : other.vertices) s.vertices.push_back(p);
    for (const Tri& t : other.triangles)
      s.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    const TetrahedralizeNotes notes = auto_repaired(s, 0.1);
    CHECK(notes.repair_used == Repair::kWrap);
    CHECK_THAT(notes.fallback_reason, Catch::Contains("surface self-intersects ("));
    // The wrap is their union: every input point on or inside it, within the offset and
    // Mesh_3's facet distance of the outer surface (the inner parts lie up to a tube
    // diameter inside: 0.6 over the diagonal of 3.0 x 2.6 x 0.6, about 0.15).
    CHECK(notes.hausdorff_mesh_to_input < 0.03);
    CHECK(notes.hausdorff_input_to_mesh < 0.2);
  }
}
