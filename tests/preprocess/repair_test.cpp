// `--repair fix` (MeshingOptions::Repair::kFix): each repair on a small generated defect of a
// cube, checked against the same input with repairs off, and the result validated.

#include <catch2/catch.hpp>
#include <string>
#include <utility>

#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/surface.hpp"

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
/// `unrepaired_error`); returns the repairs.
TetrahedralizeNotes fixed_and_refused(const TriangleMesh& s, const std::string& unrepaired_error) {
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
  return notes;
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
}
