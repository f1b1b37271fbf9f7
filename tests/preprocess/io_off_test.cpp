// The plain-OFF reader (read_plain_off) against CGAL's OFF reader, the reference it replaces
// on plain files: every libcgal-demo OFF it accepts reads to the same vertices and polygons.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/IO/OFF.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../../preprocess/src/io_text.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/testing/test_data.hpp"

namespace fs = std::filesystem;
using namespace tetseg::preprocess;

TEST_CASE("Plain OFF files read as CGAL's reader reads them", "[io][cgal]") {
  const std::string dir = TETSEG_CGAL_MESH_DIR;
  if (!tetseg::test::have_test_data(dir + "/elephant.off", "libcgal-demo meshes")) return;
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() == ".off") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  REQUIRE(files.size() > 100);
  std::size_t plain = 0;
  for (const fs::path& file : files) {
    const std::string text = detail::read_file_text(file.string());
    std::vector<Vec3> points;
    std::vector<std::vector<std::size_t>> polygons;
    if (!detail::read_plain_off(text, points, polygons)) {
      CHECK(points.empty());
      CHECK(polygons.empty());
      continue;
    }
    ++plain;
    using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_3;
    std::vector<Point> cgal_points;
    std::vector<std::vector<std::size_t>> cgal_polygons;
    const bool read = CGAL::IO::read_OFF(file.string(), cgal_points, cgal_polygons,
                                         CGAL::parameters::verbose(false));
    CAPTURE(file.filename().string(), points.size(), cgal_points.size(), polygons.size(),
            cgal_polygons.size());
    REQUIRE(read);
    REQUIRE(points.size() == cgal_points.size());
    bool same_points = true;
    for (std::size_t v = 0; v < points.size(); ++v) {
      same_points = same_points && points[v][0] == cgal_points[v].x() &&
                    points[v][1] == cgal_points[v].y() && points[v][2] == cgal_points[v].z();
    }
    CHECK(same_points);
    CHECK(polygons == cgal_polygons);
  }
  // Most demo meshes are plain OFF (the rest: COFF, NOFF, counts beside the keyword, ...).
  CAPTURE(plain, files.size());
  CHECK(plain * 2 > files.size());
}

TEST_CASE("The plain-OFF reader leaves anything unusual to CGAL", "[io]") {
  std::vector<Vec3> points;
  std::vector<std::vector<std::size_t>> polygons;
  const std::string tetra =
      "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n"
      "3 0 3 2\n3 1 2 3\n";
  REQUIRE(detail::read_plain_off(tetra, points, polygons));
  CHECK(points.size() == 4);
  CHECK(polygons ==
        std::vector<std::vector<std::size_t>>{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}});
  // Comments, a leading '+', face colours and CRLF line ends are plain OFF too.
  const std::string decorated =
      "OFF # keyword\r\n# counts\r\n4 4 0\r\n0 0 0\r\n+1 0 0\r\n0 1e0 0\r\n0 0 1 # top\r\n"
      "3 0 2 1 255 0 0\r\n3 0 1 3\r\n3 0 3 2\r\n3 1 2 3\r\n";
  REQUIRE(detail::read_plain_off(decorated, points, polygons));
  CHECK(points[1][0] == 1.0);
  CHECK(polygons.size() == 4);
  // Each of these goes to CGAL's reader (which reads or rejects it with its own message).
  for (const std::string& text : {
           std::string("COFF\n4 4 0\n") + tetra.substr(10),          // another variant
           std::string("OFF 4 4 0\n") + tetra.substr(10),            // counts beside the keyword
           std::string("OFF\n4 4 0\n0 0 0 1\n") + tetra.substr(16),  // a fourth coordinate
           std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 9\n"),  // index out of range
           std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2\n"),    // corners missing
           std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1e999\n") + tetra.substr(34),
           std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 x\n") + tetra.substr(34),
           tetra + "3 0 1 2\n",                               // trailing content
           std::string("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n"),  // truncated
       }) {
    CAPTURE(text);
    CHECK_FALSE(detail::read_plain_off(text, points, polygons));
    CHECK(points.empty());
    CHECK(polygons.empty());
  }
}

TEST_CASE("A plain OFF reads through read_triangle_mesh like any OFF", "[io]") {
  // The public reader on a file with a quad: the fast path, the quad triangulated.
  const fs::path path = fs::temp_directory_path() / "tetseg_io_off_test_quad.off";
  {
    std::ofstream out(path);
    out << "OFF\n5 5 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n4 0 3 2 1\n3 0 1 4\n3 1 2 4\n"
           "3 2 3 4\n3 3 0 4\n";
  }
  const TriangleMesh mesh = read_triangle_mesh(path.string());
  fs::remove(path);
  CHECK(mesh.vertices.size() == 5);
  CHECK(mesh.triangles.size() == 6);
}
