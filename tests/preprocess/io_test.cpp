// Tet mesh readers/writers (MEDIT, TetGen, Gmsh 2.2/4.1) and surface import through assimp.

#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>

#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/surface.hpp"

namespace fs = std::filesystem;
using namespace tetseg::preprocess;

namespace {

/// A temporary directory removed at the end of the test.
struct TempDir {
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() /
             ("tetseg_io_test_" + std::to_string(::getpid()) + "_" + name)) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }
  fs::path path;
};

/// An n^3 grid of cubes over [0,1]^3 (with an irrational jitter so coordinates need all 17
/// digits), each cube split into 6 positively oriented tets (Kuhn triangulation).
TetMesh grid_mesh(int n) {
  return tetseg::test::kuhn_grid(n, n, n, [n](int i, int j, int k) {
    return Vec3{i / double(n) + 1e-3 / 3.0 * j, j / double(n) + 1e-3 / 7.0 * k,
                k / double(n) * 1.1};
  });
}

/// Writes `mesh` to `path` (Gmsh 2.2 when `gmsh22`, else the format of the extension) and
/// returns the file's text.
std::string written_text(const std::string& path, const TetMesh& mesh, bool gmsh22) {
  if (gmsh22) {
    write_gmsh22(path, mesh);
  } else {
    write_tet_mesh(path, mesh);
  }
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

bool same_mesh(const TetMesh& a, const TetMesh& b) {
  return a.nodes == b.nodes && a.tets == b.tets;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("Tet meshes round-trip exactly through every format", "[format][io]") {
  const TempDir dir("roundtrip");
  const TetMesh mesh = grid_mesh(3);
  SECTION("Each writer's output reads back to the same nodes and tets.") {
    for (const char* name : {"a.mesh", "a.node", "b.ele", "a.msh"}) {
      CAPTURE(name);
      write_tet_mesh(dir.file(name), mesh);
      CHECK(same_mesh(read_tet_mesh(dir.file(name)), mesh));
    }
    write_gmsh22(dir.file("c.msh"), mesh);
    CHECK(same_mesh(read_tet_mesh(dir.file("c.msh")), mesh));
  }
  SECTION("A chain MEDIT -> TetGen -> Gmsh 2.2 -> Gmsh 4.1 -> MEDIT changes nothing.") {
    write_tet_mesh(dir.file("1.mesh"), mesh);
    write_tet_mesh(dir.file("2.node"), read_tet_mesh(dir.file("1.mesh")));
    write_gmsh22(dir.file("3.msh"), read_tet_mesh(dir.file("2.ele")));
    write_tet_mesh(dir.file("4.msh"), read_tet_mesh(dir.file("3.msh")));
    write_tet_mesh(dir.file("5.mesh"), read_tet_mesh(dir.file("4.msh")));
    const TetMesh back = read_tet_mesh(dir.file("5.mesh"));
    CHECK(same_mesh(back, mesh));
    const Surface s = extract_surface(back);
    CHECK(enclosed_volume(back.nodes, s.triangles) ==
          Approx(total_tet_volume(back)).epsilon(1e-12));
  }
}

TEST_CASE("The MEDIT reader accepts the format's variations", "[format][io]") {
  const TempDir dir("medit");
  SECTION("Keywords are case-insensitive, comments are skipped and other sections ignored.") {
    const std::string path = dir.write("m.mesh",
                                       "# a comment\nMeshVersionFormatted 2\ndimension\n3\n"
                                       "VERTICES 5 # five\n"
                                       "0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n1 1 1 2\n"
                                       "Edges 1\n1 2 0\nCorners 2 1 2\n"
                                       "Triangles 2\n1 2 3 0\n1 2 3 0\n"
                                       "tetrahedra 2\n1 2 3 4 0\n2 5 3 4 0\n"
                                       "Ridges 1\n1\nEnd\n");
    const TetMesh m = read_tet_mesh(path);
    REQUIRE(m.nodes.size() == 5);
    REQUIRE(m.tets.size() == 2);
    CHECK(m.tets[0] == Tet{0, 1, 2, 3});
    CHECK(m.nodes[4] == Vec3{1, 1, 1});
  }
  SECTION("A malformed number is reported with its line.") {
    const std::string path = dir.write(
        "bad.mesh", "MeshVersionFormatted 1\nDimension 3\nVertices 2\n0 0 0 0\n1 x 0 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }),
               Catch::Contains("line 5: expected a vertex coordinate, got 'x'"));
  }
  SECTION("An index out of range is reported with its line.") {
    const std::string path = dir.write(
        "range.mesh",
        "Dimension 3\nVertices 4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTetrahedra 1\n1 2 3 9 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }),
               Catch::Contains("line 8: vertex index 9 out of range (4 vertices)"));
  }
  SECTION("A NaN coordinate is rejected.") {
    const std::string path = dir.write("nan.mesh", "Dimension 3\nVertices 1\n0 nan 0 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }),
               Catch::Contains("line 3: a vertex coordinate is not finite"));
  }
  SECTION("Numbers with a plus sign are read; an overflowing one is not finite.") {
    const std::string ok =
        dir.write("plus.mesh",
                  "Dimension 3\nVertices 4\n+1.5 0 0 +0\n1 0 0 0\n0 1 0 0\n0 0 1e-400 0\n"
                  "Tetrahedra 1\n1 2 3 4 +7\n");
    const TetMesh m = read_tet_mesh(ok);
    CHECK(m.nodes[0][0] == 1.5);
    CHECK(m.nodes[3][2] == 0.0);
    const std::string big = dir.write("big.mesh", "Dimension 3\nVertices 1\n0 1e400 0 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(big); }),
               Catch::Contains("line 3: a vertex coordinate is not finite"));
  }
  SECTION("A truncated file reports an unexpected end of file.") {
    const std::string path = dir.write("eof.mesh", "Dimension 3\nVertices 3\n0 0 0 0\n1 0 0 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }), Catch::Contains("unexpected end of file"));
  }
  SECTION("An unknown keyword is an error naming it.") {
    const std::string path = dir.write("kw.mesh", "Dimension 3\nBananas 2\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }),
               Catch::Contains("line 2: unknown keyword 'Bananas'"));
  }
  SECTION("A missing file names the file.") {
    try {
      read_tet_mesh(dir.file("missing.mesh"));
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.file() == dir.file("missing.mesh"));
      CHECK_THAT(e.what(), Catch::Contains("cannot open"));
    }
  }
}

TEST_CASE("The TetGen reader accepts 0- and 1-based files with attributes", "[format][io]") {
  const TempDir dir("tetgen");
  SECTION("1-based, attributes, boundary markers, comments and 10-node tets are read.") {
    dir.write("t.node",
              "# header\n5 3 2 1\n1 0 0 0 7 8 1\n2 1 0 0 7 8 1\n3 0 1 0 7 8 1\n"
              "4 0 0 1 7 8 0 # interior?\n5 1 1 1 0 0 1\n");
    dir.write("t.ele", "2 10 1\n1 1 2 3 4 1 1 1 1 1 1 5\n2 2 5 3 4 1 1 1 1 1 1 5\n");
    const TetMesh m = read_tet_mesh(dir.file("t.ele"));
    REQUIRE(m.nodes.size() == 5);
    REQUIRE(m.tets.size() == 2);
    CHECK(m.tets[0] == Tet{0, 1, 2, 3});
    CHECK(m.tets[1] == Tet{1, 4, 2, 3});
  }
  SECTION("0-based files with CRLF line ends give the same ids.") {
    dir.write("z.node", "4 3 0 0\r\n0 0 0 0\r\n1 1 0 0\r\n2 0 1 0\r\n3 0 0 1\r\n");
    dir.write("z.ele", "1 4 0\r\n0 0 1 2 3\r\n");
    const TetMesh m = read_tet_mesh(dir.file("z.node"));
    CHECK(m.tets[0] == Tet{0, 1, 2, 3});
  }
  SECTION("An index out of range names the line and the valid range.") {
    dir.write("r.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
    dir.write("r.ele", "1 4 0\n\n1 1 2 3 5\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(dir.file("r.ele")); }),
               Catch::Contains("line 3: point index 5 out of range (1..4)"));
  }
  SECTION("A count that does not match the lines is an error.") {
    dir.write("c.node", "3 3 0 0\n1 0 0 0\n2 1 0 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(dir.file("c.node")); }),
               Catch::Contains("unexpected end of file (expected 1 more point)"));
    dir.write("d.node", "1 3 0 0\n1 0 0 0\n2 1 0 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(dir.file("d.node")); }),
               Catch::Contains("line 3: more points than the header's count 1"));
  }
  SECTION("A line with the wrong number of values is reported.") {
    dir.write("v.node", "2 3 0 1\n1 0 0 0 1\n2 1 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(dir.file("v.node")); }),
               Catch::Contains("line 3: expected 5 values, got 3"));
  }
}

TEST_CASE("The Gmsh reader handles 2.2 and 4.1 ASCII files", "[format][io]") {
  const TempDir dir("gmsh");
  SECTION("4.1 with entity blocks, sparse tags, parametric nodes and other element types.") {
    const std::string path = dir.write(
        "g.msh",
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"body\"\n$EndPhysicalNames\n"
        "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 1 1 0\n$EndEntities\n"
        "$Nodes\n2 5 10 50\n3 1 0 3\n10\n20\n30\n0 0 0\n1 0 0\n0 1 0\n"
        "2 7 1 2\n40\n50\n0 0 1 0.5 0.5\n1 1 1 0.25 0.25\n$EndNodes\n"
        "$Elements\n2 3 1 3\n2 7 2 1\n1 10 20 30\n3 1 4 2\n2 10 20 30 40\n3 20 50 30 40\n"
        "$EndElements\n$Comments\nanything $Nodes here\n$EndComments\n");
    const TetMesh m = read_tet_mesh(path);
    REQUIRE(m.nodes.size() == 5);
    REQUIRE(m.tets.size() == 2);
    CHECK(m.tets[0] == Tet{0, 1, 2, 3});
    CHECK(m.tets[1] == Tet{1, 4, 2, 3});
    CHECK(m.nodes[4] == Vec3{1, 1, 1});
  }
  SECTION("2.2 with tags, triangles and lines mixed in.") {
    const std::string path = dir.write(
        "h.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n7 0 0 0\n8 1 0 0\n9 0 1 0\n11 0 0 1\n"
        "$EndNodes\n$Elements\n3\n1 1 2 0 1 7 8\n2 2 2 0 1 7 8 9\n3 4 3 0 1 5 7 8 9 "
        "11\n$EndElements\n");
    const TetMesh m = read_tet_mesh(path);
    REQUIRE(m.tets.size() == 1);
    CHECK(m.tets[0] == Tet{0, 1, 2, 3});
  }
  SECTION("A binary header with no mesh after it is a file without tets.") {
    // (The C string ends at the first zero byte, so the int 1 is written separately.)
    const std::string path = dir.write("b.msh", std::string("$MeshFormat\n4.1 1 8\n\x01", 21) +
                                                    std::string(3, '\0') + "\n$EndMeshFormat\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }), Catch::Contains("no tetrahedra"));
  }
  SECTION("A node count that does not match its blocks is an error.") {
    const std::string path = dir.write("n.msh",
                                       "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n3 1 "
                                       "0 2\n1\n2\n0 0 0\n1 0 0\n$EndNodes\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }),
               Catch::Contains("node blocks hold 2 nodes, header says 3"));
  }
  SECTION("A tet that refers to a missing node tag names the line.") {
    const std::string path = dir.write(
        "t.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n"
        "$EndNodes\n$Elements\n1\n1 4 0 1 2 3 99\n$EndElements\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }),
               Catch::Contains("line 13: node tag 99 out of range"));
  }
  SECTION("An infinite coordinate is rejected with its line.") {
    const std::string path = dir.write(
        "i.msh",
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n1 0 0 0\n2 inf 0 0\n$EndNodes\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }),
               Catch::Contains("line 7: a node coordinate is not finite"));
  }
  SECTION("A missing end marker is an unexpected end of file.") {
    const std::string path =
        dir.write("e.msh", "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 0\n");
    CHECK_THAT(error_of([&] { read_tet_mesh(path); }), Catch::Contains("unexpected end of file"));
  }
}

TEST_CASE("A mesh whose tets are all negatively oriented is flipped on reading", "[format][io]") {
  const TempDir dir("flip");
  dir.write("f.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
  dir.write("f.ele", "1 4 0\n0 0 2 1 3\n");
  const TetMesh m = read_tet_mesh(dir.file("f.ele"));
  CHECK(total_tet_volume(m) == Approx(1.0 / 6.0));
}

TEST_CASE("Surfaces are imported through assimp with coincident vertices merged",
          "[format][io][assimp]") {
  const TempDir dir("assimp");
  // A unit cube: 8 corners, 12 outward triangles.
  const double c[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                          {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  const int f[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                        {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  auto check_cube = [](const TriangleMesh& m) {
    CHECK(m.vertices.size() == 8);
    CHECK(m.triangles.size() == 12);
    CHECK(enclosed_volume(m.vertices, m.triangles) == Approx(1.0));
    validate_closed_surface(m, "cube");
  };
  SECTION("OFF with a quad-free triangle list.") {
    std::string text = "OFF\n8 12 0\n";
    for (const auto& p : c)
      text += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    for (const auto& t : f)
      text += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " +
              std::to_string(t[2]) + "\n";
    check_cube(read_triangle_mesh(dir.write("cube.off", text)));
  }
  SECTION("OBJ with quads is triangulated.") {
    std::string text;
    for (const auto& p : c)
      text += "v " + std::to_string(p[0]) + " " + std::to_string(p[1]) + " " +
              std::to_string(p[2]) + "\n";
    const int q[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                         {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    for (const auto& t : q)
      text += "f " + std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " +
              std::to_string(t[2] + 1) + " " + std::to_string(t[3] + 1) + "\n";
    check_cube(read_triangle_mesh(dir.write("cube.obj", text)));
  }
  SECTION("ASCII STL repeats every corner; vertices are merged by position.") {
    std::string text = "solid cube\n";
    for (const auto& t : f) {
      text += " facet normal 0 0 0\n  outer loop\n";
      for (int k : t)
        text += "   vertex " + std::to_string(c[k][0]) + " " + std::to_string(c[k][1]) + " " +
                std::to_string(c[k][2]) + "\n";
      text += "  endloop\n endfacet\n";
    }
    text += "endsolid cube\n";
    check_cube(read_triangle_mesh(dir.write("cube.stl", text)));
  }
  SECTION("ASCII PLY with a face list.") {
    std::string text =
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
        "property float z\nelement face 12\nproperty list uchar int vertex_indices\nend_header\n";
    for (const auto& p : c)
      text += std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) + "\n";
    for (const auto& t : f)
      text += "3 " + std::to_string(t[0]) + " " + std::to_string(t[1]) + " " +
              std::to_string(t[2]) + "\n";
    check_cube(read_triangle_mesh(dir.write("cube.ply", text)));
  }
  SECTION("A file with no triangles is an error.") {
    const std::string path = dir.write("empty.obj", "v 0 0 0\nv 1 0 0\n");
    CHECK_THROWS_AS(read_triangle_mesh(path), InputError);
  }
  SECTION("A missing file is an error naming it.") {
    CHECK_THAT(error_of([&] { read_triangle_mesh(dir.file("nope.obj")); }),
               Catch::Contains("cannot open"));
  }
}

TEST_CASE("Every truncated prefix of a valid file reads or fails with InputError", "[format][io]") {
  const TempDir dir("prefix");
  const TetMesh mesh = grid_mesh(1);
  for (const char* name : {"p.mesh", "p.msh", "q.msh", "p.node"}) {
    CAPTURE(name);
    const std::string path = dir.file(name);
    const std::string text = written_text(path, mesh, std::string(name) == "q.msh");
    std::size_t failures = 0;
    std::size_t tried = 0;
    // Every 5th prefix, and every one of the last 60 (where a cut can leave a full mesh).
    for (std::size_t n = 0; n < text.size(); n += (n + 60 < text.size() ? 5 : 1)) {
      ++tried;
      dir.write(name, text.substr(0, n));
      try {
        const TetMesh m = read_tet_mesh(path);
        // Only a cut inside the last line or the end marker can leave a complete file.
        CHECK(n + 40 >= text.size());
        CHECK(m.tets.size() == mesh.tets.size());
        for (const Tet& t : m.tets)
          for (std::uint32_t v : t) CHECK(v < m.nodes.size());
      } catch (const InputError&) {
        ++failures;
      }
    }
    CHECK(failures + 40 >= tried);
  }
}

TEST_CASE("Random byte changes never crash a reader", "[format][io]") {
  const TempDir dir("flips");
  const TetMesh mesh = grid_mesh(1);
  std::mt19937 rng(12345);
  const char kBytes[] = {'0', '9', '-', '.', 'e', ' ', '\n', '$', '#', 'x', '\0', '\xff'};
  for (const char* name : {"f.mesh", "f.msh", "g.msh", "f.node"}) {
    CAPTURE(name);
    const std::string path = dir.file(name);
    const std::string text = written_text(path, mesh, std::string(name) == "g.msh");
    for (int trial = 0; trial < 120; ++trial) {
      std::string changed = text;
      for (int k = 0; k < 1 + trial % 3; ++k)
        changed[rng() % changed.size()] = kBytes[rng() % sizeof kBytes];
      dir.write(name, changed);
      try {
        const TetMesh m = read_tet_mesh(path);
        for (const Tet& t : m.tets)
          for (std::uint32_t v : t) REQUIRE(v < m.nodes.size());
        for (const Vec3& p : m.nodes)
          for (double c : p) REQUIRE(std::isfinite(c));
      } catch (const InputError&) {
      }
    }
  }
}
