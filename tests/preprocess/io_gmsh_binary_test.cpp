// Binary Gmsh (MSH 2.2 and 4.1): files assembled byte by byte here from the format's rules
// (independent of the writer), both byte orders, round trips through the binary writer, and
// hostile counts.

#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/preprocess/io.hpp"

namespace fs = std::filesystem;
using namespace tetseg::preprocess;

namespace {

std::string temp_file(const std::string& name) {
  return (fs::temp_directory_path() /
          ("tetseg_gmsh_bin_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

/// Appends `value` in little- (default) or big-endian byte order, independent of the host.
template <class T>
void put(std::string& out, T value, bool big_endian = false) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  const std::uint16_t probe = 1;
  const bool host_little = *reinterpret_cast<const unsigned char*>(&probe) == 1;
  if (host_little == big_endian) std::reverse(raw, raw + sizeof(T));
  out.append(reinterpret_cast<const char*>(raw), sizeof(T));
}

/// Two tets sharing a face, nodes tagged 10, 20, ... (sparse tags), plus a triangle element
/// the reader must step over.
const Vec3 kNodes[5] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
const Tet kTets[2] = {{0, 1, 2, 3}, {1, 2, 3, 4}};

void check_two_tets(const TetMesh& m) {
  REQUIRE(m.nodes.size() == 5);
  for (std::size_t i = 0; i < 5; ++i) CHECK(m.nodes[i] == kNodes[i]);
  REQUIRE(m.tets.size() == 2);
  // Both tets are positively oriented as written, so they are kept in file order.
  CHECK(m.tets[0] == kTets[0]);
  CHECK(m.tets[1] == kTets[1]);
}

/// MSH 2.2 binary: ASCII counts, then per node int tag + 3 doubles; elements as blocks of
/// (type, count, tag count) headers followed by (number, tags..., nodes...) ints.
std::string msh22_binary(bool big_endian) {
  std::string out = "$MeshFormat\n2.2 1 8\n";
  put<std::int32_t>(out, 1, big_endian);
  out += "\n$EndMeshFormat\n$Nodes\n5\n";
  for (int i = 0; i < 5; ++i) {
    put<std::int32_t>(out, 10 * (i + 1), big_endian);
    for (double c : kNodes[i]) put<double>(out, c, big_endian);
  }
  out += "\n$EndNodes\n$Elements\n3\n";
  // One triangle (type 2) with 2 tags.
  for (std::int32_t v : {2, 1, 2, 7, 0, 0, 10, 20, 30}) put<std::int32_t>(out, v, big_endian);
  // Two tets (type 4) with 1 tag each, in one block.
  for (std::int32_t v : {4, 2, 1}) put<std::int32_t>(out, v, big_endian);
  for (int e = 0; e < 2; ++e) {
    put<std::int32_t>(out, 8 + e, big_endian);
    put<std::int32_t>(out, 1, big_endian);
    for (std::uint32_t n : kTets[e]) put<std::int32_t>(out, 10 * (n + 1), big_endian);
  }
  out += "\n$EndElements\n";
  return out;
}

/// MSH 4.1 binary with 8-byte size fields: an $Entities section (skipped), two node blocks
/// (one parametric on a surface), a triangle block and a tet block.
std::string msh41_binary(bool big_endian) {
  std::string out = "$MeshFormat\n4.1 1 8\n";
  put<std::int32_t>(out, 1, big_endian);
  out += "\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 \"solid\"\n$EndPhysicalNames\n$Entities\n";
  for (std::uint64_t v : {0, 0, 0, 1}) put<std::uint64_t>(out, v, big_endian);
  put<std::int32_t>(out, 1, big_endian);
  for (double c : {0.0, 0.0, 0.0, 1.0, 1.0, 1.0}) put<double>(out, c, big_endian);
  put<std::uint64_t>(out, 0, big_endian);
  put<std::uint64_t>(out, 0, big_endian);
  out += "\n$EndEntities\n$Nodes\n";
  for (std::uint64_t v : {2, 5, 10, 50}) put<std::uint64_t>(out, v, big_endian);
  // Block 1: surface entity (dim 2), parametric: 2 nodes with u, v after x, y, z.
  for (std::int32_t v : {2, 1, 1}) put<std::int32_t>(out, v, big_endian);
  put<std::uint64_t>(out, 2, big_endian);
  for (std::uint64_t tag : {10, 20}) put<std::uint64_t>(out, tag, big_endian);
  for (int i = 0; i < 2; ++i) {
    for (double c : kNodes[i]) put<double>(out, c, big_endian);
    put<double>(out, 0.25, big_endian);
    put<double>(out, 0.75, big_endian);
  }
  // Block 2: volume entity, not parametric: 3 nodes.
  for (std::int32_t v : {3, 1, 0}) put<std::int32_t>(out, v, big_endian);
  put<std::uint64_t>(out, 3, big_endian);
  for (std::uint64_t tag : {30, 40, 50}) put<std::uint64_t>(out, tag, big_endian);
  for (int i = 2; i < 5; ++i)
    for (double c : kNodes[i]) put<double>(out, c, big_endian);
  out += "\n$EndNodes\n$Elements\n";
  for (std::uint64_t v : {2, 3, 1, 3}) put<std::uint64_t>(out, v, big_endian);
  for (std::int32_t v : {2, 1, 2}) put<std::int32_t>(out, v, big_endian);  // triangles
  put<std::uint64_t>(out, 1, big_endian);
  for (std::uint64_t v : {1, 10, 20, 30}) put<std::uint64_t>(out, v, big_endian);
  for (std::int32_t v : {3, 1, 4}) put<std::int32_t>(out, v, big_endian);  // tets
  put<std::uint64_t>(out, 2, big_endian);
  for (int e = 0; e < 2; ++e) {
    put<std::uint64_t>(out, static_cast<std::uint64_t>(2 + e), big_endian);
    for (std::uint32_t n : kTets[e]) put<std::uint64_t>(out, 10 * (n + 1), big_endian);
  }
  out += "\n$EndElements\n";
  return out;
}

std::string error_of(const std::string& path) {
  try {
    read_tet_mesh(path);
  } catch (const InputError& e) {
    CHECK(e.file() == path);
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("Binary Gmsh files written by the format's rules are read", "[format][io][gmsh]") {
  const std::string path = temp_file("rules.msh");
  // Both byte orders of both versions (plain blocks: a SECTION inside the loop would run for
  // the first byte order only).
  for (const bool big_endian : {false, true}) {
    CAPTURE(big_endian);
    {
      INFO("MSH 2.2 binary with tags, a triangle and sparse node tags.");
      write_bytes(path, msh22_binary(big_endian));
      check_two_tets(read_tet_mesh(path));
    }
    {
      INFO("MSH 4.1 binary with entities, physical names and a parametric node block.");
      write_bytes(path, msh41_binary(big_endian));
      check_two_tets(read_tet_mesh(path));
    }
  }
  SECTION("A file whose endianness check is not 1 in either byte order is refused.") {
    std::string bytes = msh41_binary(false);
    const std::size_t at = bytes.find("8\n") + 2;
    bytes[at] = 2;
    write_bytes(path, bytes);
    CHECK_THAT(error_of(path), Catch::Contains("endianness"));
  }
  fs::remove(path);
}

TEST_CASE("Binary Gmsh 4.1 round-trips bit-exactly", "[format][io][gmsh]") {
  const TetMesh mesh = tetseg::test::kuhn_grid(3, 2, 2, [](int i, int j, int k) {
    return Vec3{i / 3.0 + 1e-3 / 7.0 * j, j / 2.0 + k / 11.0, k * 0.1 + i * 1e-17};
  });
  const std::string a = temp_file("a.msh");
  const std::string b = temp_file("b.msh");
  write_gmsh41_binary(a, mesh);
  const TetMesh back = read_tet_mesh(a);
  CHECK(back.nodes == mesh.nodes);
  CHECK(back.tets == mesh.tets);
  SECTION("The header is the format's: version 4.1, file type 1, size 8, then the int 1.") {
    const std::string bytes = read_bytes(a);
    REQUIRE(bytes.compare(0, 20, "$MeshFormat\n4.1 1 8\n") == 0);
    std::int32_t one = 0;
    std::memcpy(&one, bytes.data() + 20, 4);
    CHECK(one == 1);  // little-endian host (the test machine)
  }
  SECTION("Binary -> ASCII 4.1 -> binary gives the same bytes.") {
    write_tet_mesh(b, back);
    write_gmsh41_binary(b, read_tet_mesh(b));
    CHECK(read_bytes(a) == read_bytes(b));
  }
  fs::remove(a);
  fs::remove(b);
}

TEST_CASE("Hostile binary Gmsh files fail with an InputError naming the file",
          "[format][io][gmsh]") {
  const std::string path = temp_file("hostile.msh");
  const std::string good41 = msh41_binary(false);
  const std::string good22 = msh22_binary(false);
  SECTION("A huge node count in MSH 4.1 is refused before anything is reserved.") {
    std::string bytes = good41;
    const std::size_t at = bytes.find("$Nodes\n") + 7 + 8;  // numNodes
    for (int k = 0; k < 8; ++k) bytes[at + static_cast<std::size_t>(k)] = '\x7f';
    write_bytes(path, bytes);
    CHECK_THAT(error_of(path), Catch::Contains("exceeds the bytes left"));
  }
  SECTION("A negative ASCII node count in MSH 2.2 is refused.") {
    std::string bytes = good22;
    bytes.replace(bytes.find("$Nodes\n5\n"), 9, "$Nodes\n-5\n");
    write_bytes(path, bytes);
    CHECK_THAT(error_of(path), Catch::Contains("invalid node count"));
  }
  SECTION("A NaN coordinate is refused.") {
    std::string bytes = good22;
    const std::size_t at = bytes.find("$Nodes\n5\n") + 9 + 4;
    const double nan = std::nan("");
    std::memcpy(&bytes[at], &nan, 8);
    write_bytes(path, bytes);
    CHECK_THAT(error_of(path), Catch::Contains("not finite"));
  }
  SECTION("Every truncated prefix fails cleanly or reads the whole mesh.") {
    for (const std::string* good : {&good22, &good41}) {
      for (std::size_t n = 0; n < good->size(); ++n) {
        write_bytes(path, good->substr(0, n));
        try {
          const TetMesh m = read_tet_mesh(path);
          // Only the end marker may be cut.
          CHECK(n + std::string("\n$EndElements\n").size() >= good->size());
          check_two_tets(m);
        } catch (const InputError& e) {
          CHECK(e.file() == path);
        }
      }
    }
  }
  fs::remove(path);
}
