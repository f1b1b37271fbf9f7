// Mutation test of every reader (surfaces: OFF, PLY ASCII and binary, OBJ, STL ASCII and
// binary; tet meshes: MEDIT, TetGen, Gmsh 2.2 and 4.1 ASCII, Gmsh 4.1 binary): truncations,
// byte changes, hostile numbers in place of counts, indices and coordinates. A reader either
// returns a mesh whose indices are in range and whose coordinates are finite, or throws
// InputError naming the file; nothing else (a signal ends the test run).

#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "preprocess/support/grid_mesh.hpp"
#include "tetseg/preprocess/io.hpp"

namespace fs = std::filesystem;
using namespace tetseg::preprocess;

namespace {

struct Sample {
  std::string name;   ///< file name (the extension picks the reader)
  std::string bytes;  ///< a valid file
  bool binary;        ///< mutate fields as binary numbers rather than text tokens
};

const double kCube[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
const int kQuads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                          {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};

std::string point_text(const double* p) {
  std::ostringstream out;
  out << p[0] << ' ' << p[1] << ' ' << p[2];
  return out.str();
}

template <class T>
void put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof(T));
}

/// The unit cube of 6 quads in every surface format (STL: 12 triangles).
std::vector<Sample> surface_samples() {
  std::vector<Sample> samples;
  std::string off = "OFF\n8 6 0\n";
  for (const auto& p : kCube) off += point_text(p) + "\n";
  for (const auto& q : kQuads)
    off += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
           " " + std::to_string(q[3]) + "\n";
  samples.push_back({"cube.off", off, false});

  std::string obj = "# cube\n";
  for (const auto& p : kCube) obj += "v " + point_text(p) + "\n";
  for (const auto& q : kQuads)
    obj += "f " + std::to_string(q[0] + 1) + " " + std::to_string(q[1] + 1) + " " +
           std::to_string(q[2] + 1) + " " + std::to_string(q[3] + 1) + "\n";
  samples.push_back({"cube.obj", obj, false});

  const std::string ply_header =
      "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 6\nproperty list uchar int vertex_indices\nend_header\n";
  std::string ply = "ply\nformat ascii 1.0\n" + ply_header;
  for (const auto& p : kCube) ply += point_text(p) + "\n";
  for (const auto& q : kQuads)
    ply += "4 " + std::to_string(q[0]) + " " + std::to_string(q[1]) + " " + std::to_string(q[2]) +
           " " + std::to_string(q[3]) + "\n";
  samples.push_back({"cube.ply", ply, false});

  std::string ply_binary = "ply\nformat binary_little_endian 1.0\n" + ply_header;
  for (const auto& p : kCube)
    for (int k = 0; k < 3; ++k) put<float>(ply_binary, static_cast<float>(p[k]));
  for (const auto& q : kQuads) {
    put<std::uint8_t>(ply_binary, 4);
    for (int k = 0; k < 4; ++k) put<std::int32_t>(ply_binary, q[k]);
  }
  samples.push_back({"cube_binary.ply", ply_binary, true});

  std::string stl = "solid cube\n";
  std::string stl_binary(80, ' ');
  put<std::uint32_t>(stl_binary, 12);
  for (const auto& q : kQuads)
    for (int half = 0; half < 2; ++half) {
      const int corners[3] = {q[0], q[1 + half], q[2 + half]};
      stl += "facet normal 0 0 0\nouter loop\n";
      for (int k = 0; k < 3; ++k) put<float>(stl_binary, 0.0f);
      for (int c : corners) {
        stl += "vertex " + point_text(kCube[c]) + "\n";
        for (int k = 0; k < 3; ++k) put<float>(stl_binary, static_cast<float>(kCube[c][k]));
      }
      put<std::uint16_t>(stl_binary, 0);
      stl += "endloop\nendfacet\n";
    }
  stl += "endsolid cube\n";
  samples.push_back({"cube.stl", stl, false});
  samples.push_back({"cube_binary.stl", stl_binary, true});
  return samples;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

/// A 2x1x1 Kuhn grid in every tet-mesh format, as the writers write it.
std::vector<Sample> tet_samples(const fs::path& dir) {
  const TetMesh mesh = tetseg::test::kuhn_grid(2, 1, 1, [](int i, int j, int k) {
    return Vec3{i * 0.5, j + 0.1 * i, k * 1.5};
  });
  std::vector<Sample> samples;
  auto add = [&](const std::string& name, const std::function<void(const std::string&)>& write,
                 bool binary) {
    const std::string path = (dir / name).string();
    write(path);
    samples.push_back({name, file_bytes(path), binary});
    fs::remove(path);
  };
  add(
      "grid.mesh", [&](const std::string& p) { write_tet_mesh(p, mesh); }, false);
  add(
      "grid41.msh", [&](const std::string& p) { write_tet_mesh(p, mesh); }, false);
  add(
      "grid22.msh", [&](const std::string& p) { write_gmsh22(p, mesh); }, false);
  add(
      "grid_binary.msh", [&](const std::string& p) { write_gmsh41_binary(p, mesh); }, true);
  // TetGen: the .ele is mutated beside an intact .node, and the other way round.
  const std::string node = (dir / "grid.node").string();
  write_tet_mesh(node, mesh);
  samples.push_back({"grid.node", file_bytes(node), false});
  samples.push_back({"grid.ele", file_bytes((dir / "grid.ele").string()), false});
  return samples;
}

/// Byte ranges of the number tokens of a text file.
std::vector<std::pair<std::size_t, std::size_t>> number_tokens(const std::string& text) {
  std::vector<std::pair<std::size_t, std::size_t>> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    const std::size_t start = i;
    while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i > start && (std::isdigit(static_cast<unsigned char>(text[start])) || text[start] == '-'))
      tokens.emplace_back(start, i - start);
  }
  return tokens;
}

/// The mutations of one valid file: every prefix (every 3rd for long files), 150 random byte
/// changes, and hostile numbers in place of number tokens (text) or 4-byte fields (binary).
std::vector<std::string> mutations(const Sample& sample, std::mt19937& rng) {
  const std::string& good = sample.bytes;
  std::vector<std::string> out;
  const std::size_t step = good.size() > 600 ? 3 : 1;
  for (std::size_t n = 0; n < good.size(); n += step) out.push_back(good.substr(0, n));
  const char kBytes[] = {'0', '9', '-', '.', 'e', ' ', '\n', '$', '#', 'x', '\0', '\xff', '\x7f'};
  for (int trial = 0; trial < 150; ++trial) {
    std::string changed = good;
    for (int k = 0; k < 1 + trial % 3; ++k)
      changed[rng() % changed.size()] = kBytes[rng() % sizeof kBytes];
    out.push_back(changed);
  }
  if (sample.binary) {
    const std::uint32_t kFields[] = {
        0xffffffffu, 0x7fffffffu, 0x80000000u, 0x7fc00000u /* NaN */, 0x7f800000u /* +Inf */,
        0x0000ffffu};
    for (int trial = 0; trial < 120; ++trial) {
      std::string changed = good;
      const std::size_t at = rng() % (good.size() - 4);
      const std::uint32_t v = kFields[static_cast<std::size_t>(trial) % 6];
      std::memcpy(&changed[at], &v, 4);
      out.push_back(changed);
    }
  } else {
    const char* kNumbers[] = {
        "-1",    "-2147483649", "2147483647", "4294967296", "99999999999999999999",
        "1e308", "nan",         "inf"};
    const auto tokens = number_tokens(good);
    for (std::size_t t = 0; t < tokens.size(); ++t) {
      // Every token of the first 12 (headers, counts) with every number, then a sample.
      if (t >= 12 && rng() % 4 != 0) continue;
      for (const char* number : kNumbers) {
        std::string changed = good;
        changed.replace(tokens[t].first, tokens[t].second, number);
        out.push_back(changed);
      }
    }
  }
  return out;
}

/// Reads `path` with the reader of its kind; returns 1 when it read, 0 on InputError.
int read_checked(const std::string& path, bool surface) {
  try {
    if (surface) {
      const TriangleMesh m = read_triangle_mesh(path);
      for (const Tri& t : m.triangles)
        for (std::uint32_t v : t) REQUIRE(v < m.vertices.size());
      for (const Vec3& p : m.vertices)
        for (double c : p) REQUIRE(std::isfinite(c));
    } else {
      const TetMesh m = read_tet_mesh(path);
      for (const Tet& t : m.tets)
        for (std::uint32_t v : t) REQUIRE(v < m.nodes.size());
      for (const Vec3& p : m.nodes)
        for (double c : p) REQUIRE(std::isfinite(c));
    }
    return 1;
  } catch (const InputError& e) {
    REQUIRE(e.file().find(fs::path(path).stem().string()) != std::string::npos);
    REQUIRE(std::string(e.what()).size() > 0);
    return 0;
  }
}

}  // namespace

TEST_CASE("Every reader survives truncation, byte changes, hostile counts and NaN",
          "[format][io][mutation]") {
  const fs::path dir =
      fs::temp_directory_path() / ("tetseg_mutation_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::mt19937 rng(2026);
  std::vector<std::pair<Sample, bool>> all;
  for (const Sample& s : surface_samples()) all.emplace_back(s, true);
  for (const Sample& s : tet_samples(dir)) all.emplace_back(s, false);
  // TetGen needs both files: keep intact copies beside the one being mutated.
  std::ofstream(dir / "grid.node", std::ios::binary) << all[all.size() - 2].first.bytes;
  std::ofstream(dir / "grid.ele", std::ios::binary) << all[all.size() - 1].first.bytes;
  for (const auto& [sample, surface] : all) {
    CAPTURE(sample.name);
    const std::string path = (dir / sample.name).string();
    // The unmutated file reads.
    std::ofstream(path, std::ios::binary) << sample.bytes;
    REQUIRE(read_checked(path, surface) == 1);
    std::size_t read = 0;
    std::size_t refused = 0;
    for (const std::string& bytes : mutations(sample, rng)) {
      {
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        out << bytes;
      }
      (read_checked(path, surface) == 1 ? read : refused) += 1;
    }
    // Most mutations break the file; some (a changed digit) leave a readable one.
    CHECK(refused > read / 4);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << sample.bytes;
  }
  fs::remove_all(dir);
}
