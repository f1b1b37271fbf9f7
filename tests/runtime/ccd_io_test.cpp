// Readers of the CCD reference data (testing/include/tetseg/testing/ccd_io.hpp): PLY variants, JSON
// arrays, the edge numbering of the scalable-CCD data (checked against the data's own query CSVs).

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "tetseg/testing/ccd_io.hpp"
#include "tetseg/testing/test_data.hpp"

namespace {

namespace fs = std::filesystem;
namespace io = tetseg::test::ccd_io;

fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(TETSEG_BINARY_DIR) / "test-scratch" / "ccd_io";
  fs::create_directories(dir);
  return dir / name;
}

void write_bytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

template <class T>
std::string raw(T value, bool big_endian) {
  std::string s(sizeof(T), '\0');
  std::memcpy(&s[0], &value, sizeof(T));
  if (big_endian) std::reverse(s.begin(), s.end());
  return s;
}

const std::vector<io::Vec3> kPoints{{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5}, {1, 1, -2.25}};
const std::vector<std::array<std::uint32_t, 3>> kFaces{{0, 1, 2}, {1, 3, 2}};

/// A binary PLY of kPoints/kFaces with the given scalar type, endianness and an extra colour.
template <class T>
std::string binary_ply(bool big_endian, const char* type) {
  std::string s = std::string("ply\nformat ") +
                  (big_endian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\ncomment test\nelement vertex 4\nproperty " + type + " x\nproperty " +
                  type + " y\nproperty " + type + " z\nproperty uchar red\nelement face 2\n" +
                  "property list uchar int vertex_indices\nproperty uchar flags\nend_header\n";
  for (const auto& p : kPoints) {
    for (double c : p) s += raw(static_cast<T>(c), big_endian);
    s += '\x7f';
  }
  for (const auto& f : kFaces) {
    s += '\x03';
    for (auto i : f) s += raw(static_cast<std::int32_t>(i), big_endian);
    s += '\x01';
  }
  return s;
}

}  // namespace

TEST_CASE("PLY triangle soups are read in every variant of the data.", "[ccd][io]") {
  SECTION("Binary little-endian doubles with extra properties are read exactly.") {
    write_bytes(scratch("le.ply"), binary_ply<double>(false, "double"));
    const io::Mesh m = io::read_ply(scratch("le.ply").string());
    CHECK(m.vertices == kPoints);
    CHECK(m.faces == kFaces);
  }
  SECTION("Binary big-endian floats are read exactly.") {
    write_bytes(scratch("be.ply"), binary_ply<float>(true, "float"));
    const io::Mesh m = io::read_ply(scratch("be.ply").string());
    CHECK(m.vertices == kPoints);
    CHECK(m.faces == kFaces);
  }
  SECTION("ASCII files are read.") {
    write_bytes(
        scratch("a.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0.5\n1 1 -2.25\n3 0 1 2\n3 1 3 2\n");
    const io::Mesh m = io::read_ply(scratch("a.ply").string());
    CHECK(m.vertices == kPoints);
    CHECK(m.faces == kFaces);
  }
  SECTION("Truncated data, out-of-range indices and non-triangles are rejected.") {
    const std::string good = binary_ply<double>(false, "double");
    write_bytes(scratch("t.ply"), good.substr(0, good.size() - 3));
    CHECK_THROWS(io::read_ply(scratch("t.ply").string()));
    write_bytes(
        scratch("i.ply"),
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n3 0 0 1\n");
    CHECK_THROWS(io::read_ply(scratch("i.ply").string()));
    write_bytes(
        scratch("q.ply"),
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n1 1 0\n4 0 1 3 2\n");
    CHECK_THROWS(io::read_ply(scratch("q.ply").string()));
    write_bytes(scratch("n.ply"), "solid x\n");
    CHECK_THROWS(io::read_ply(scratch("n.ply").string()));
  }
}

TEST_CASE("Flat JSON arrays of pairs and booleans are parsed strictly.", "[ccd][io]") {
  CHECK(io::parse_json_pairs(" [[1, 2],[30,4]]\n") ==
        std::vector<std::array<std::int64_t, 2>>{{1, 2}, {30, 4}});
  CHECK(io::parse_json_pairs("[]").empty());
  CHECK(io::parse_json_bools("[true,false, true]") == std::vector<bool>{true, false, true});
  CHECK_THROWS(io::parse_json_pairs("[[1,2],[3]]"));
  CHECK_THROWS(io::parse_json_pairs("[[1,2]"));
  CHECK_THROWS(io::parse_json_bools("[true,maybe]"));
  CHECK_THROWS(io::parse_json_bools("[true"));
}

TEST_CASE("Edges are numbered as in the scalable-CCD data.", "[ccd][io]") {
  SECTION("Unique undirected edges sorted by larger then smaller endpoint.") {
    const auto edges = io::unique_edges(kFaces);
    CHECK(edges ==
          std::vector<std::array<std::uint32_t, 2>>{{0, 1}, {0, 2}, {1, 2}, {1, 3}, {2, 3}});
  }
  SECTION("The numbering reproduces the coordinates of the data's own query CSVs.") {
    const fs::path dir =
        fs::path(TETSEG_SHARED_DIR) / "data/ccd-queries/sample-scalable-ccd-data/cloth-funnel";
    if (!tetseg::test::have_test_data((dir / "queries").string(), "cloth-funnel queries")) return;
    const io::Mesh m0 = io::read_ply((dir / "frames/227.ply").string());
    const io::Mesh m1 = io::read_ply((dir / "frames/228.ply").string());
    const auto edges = io::unique_edges(m0.faces);
    const auto n_v = static_cast<std::int64_t>(m0.vertices.size());
    const auto n_e = static_cast<std::int64_t>(edges.size());
    CHECK(n_e == 27930);
    for (const char* kind : {"vf", "ee"}) {
      const auto boxes = io::parse_json_pairs(
          io::read_text((dir / "boxes" / (std::string("227") + kind + ".json")).string()));
      const auto queries =
          io::read_query_csv((dir / "queries" / (std::string("227") + kind + ".csv")).string());
      REQUIRE(boxes.size() == queries.size());
      for (std::size_t i = 0; i < boxes.size(); ++i) {
        std::array<std::uint32_t, 4> ids{};
        if (kind[0] == 'v') {
          const auto& f = m0.faces.at(static_cast<std::size_t>(boxes[i][1] - n_v - n_e));
          ids = {static_cast<std::uint32_t>(boxes[i][0]), f[0], f[1], f[2]};
        } else {
          const auto& e = edges.at(static_cast<std::size_t>(boxes[i][0] - n_v));
          const auto& g = edges.at(static_cast<std::size_t>(boxes[i][1] - n_v));
          ids = {e[0], e[1], g[0], g[1]};
        }
        for (std::size_t k = 0; k < 4; ++k) {
          CHECK(queries[i].points[k] == m0.vertices.at(ids[k]));
          CHECK(queries[i].points[k + 4] == m1.vertices.at(ids[k]));
        }
      }
    }
  }
}
