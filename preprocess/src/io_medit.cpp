// MEDIT .mesh (GMF ASCII) reader and writer.

#include <algorithm>
#include <cctype>
#include <string>
#include <utility>
#include <vector>

#include "io_text.hpp"

namespace tetseg::preprocess::detail {
namespace {

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

/// Number of values per entry of the sections we skip (indices or coordinates and a ref).
int skipped_arity(const std::string& keyword) {
  static const std::pair<const char*, int> kArity[] = {
      {"edges", 3},
      {"triangles", 4},
      {"quadrilaterals", 5},
      {"hexahedra", 9},
      {"prisms", 7},
      {"pyramids", 6},
      {"corners", 1},
      {"ridges", 1},
      {"requiredvertices", 1},
      {"requirededges", 1},
      {"requiredtriangles", 1},
      {"requiredquadrilaterals", 1},
      {"normals", 3},
      {"tangents", 3},
      {"normalatvertices", 2},
      {"normalattrianglevertices", 3},
      {"normalatquadrilateralvertices", 3},
      {"tangentatedgevertices", 3},
      {"edgesp2", 4},
      {"trianglesp2", 7},
      {"tetrahedrap2", 11},
      {"crack", 2},
      {"geometricedges", 2},
      {"geometrictriangles", 2},
  };
  for (const auto& [name, arity] : kArity)
    if (keyword == name) return arity;
  return -1;
}

std::size_t read_count(Tokenizer& tok, const std::string& section, std::size_t max_count) {
  const std::int64_t n = tok.next_int("an entry count");
  if (n < 0) tok.fail("negative count " + std::to_string(n) + " in " + section);
  if (static_cast<std::uint64_t>(n) > max_count)
    tok.fail(section + " count " + std::to_string(n) + " exceeds what the file can hold");
  return static_cast<std::size_t>(n);
}

}  // namespace

TetMesh read_medit(const std::string& path) {
  const std::string text = read_file_text(path);
  Tokenizer tok(path, text, '#');
  TetMesh mesh;
  // Tets that referred to a node not read yet, with their lines: checked once all sections
  // are read (every other tet is in range then too, since nodes are only added).
  std::vector<std::pair<std::size_t, std::size_t>> pending_tets;
  const std::size_t max_count = text.size() / 2 + 1;
  bool saw_dimension = false;
  while (true) {
    const std::string_view raw = tok.next_or_end();
    if (raw.empty()) break;
    const std::string keyword = lower(raw);
    if (keyword == "end") break;
    if (keyword == "meshversionformatted") {
      const std::int64_t version = tok.next_int("a format version");
      if (version < 1 || version > 4)
        tok.fail("unsupported MeshVersionFormatted " + std::to_string(version));
    } else if (keyword == "dimension") {
      const std::int64_t dim = tok.next_int("a dimension");
      if (dim != 3) tok.fail("dimension " + std::to_string(dim) + " is not 3");
      saw_dimension = true;
    } else if (keyword == "vertices") {
      const std::size_t n = read_count(tok, "Vertices", max_count / 4);
      mesh.nodes.reserve(mesh.nodes.size() + n);
      for (std::size_t i = 0; i < n; ++i) {
        Vec3 p;
        p[0] = tok.next_double("a vertex coordinate");
        p[1] = tok.next_double("a vertex coordinate");
        p[2] = tok.next_double("a vertex coordinate");
        tok.next_int("a vertex reference");
        mesh.nodes.push_back(p);
      }
    } else if (keyword == "tetrahedra") {
      const std::size_t n = read_count(tok, "Tetrahedra", max_count / 5);
      mesh.tets.reserve(mesh.tets.size() + n);
      for (std::size_t i = 0; i < n; ++i) {
        Tet t;
        bool pending = false;
        for (int k = 0; k < 4; ++k) {
          const std::int64_t index = tok.next_int("a vertex index");
          if (index < 1 || index > static_cast<std::int64_t>(UINT32_MAX))
            tok.fail("vertex index " + std::to_string(index) +
                     " out of range (indices are 1-based)");
          t[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(index - 1);
          pending |= static_cast<std::size_t>(index) > mesh.nodes.size();
        }
        if (pending) pending_tets.emplace_back(mesh.tets.size(), tok.line());
        tok.next_int("a tetrahedron reference");
        mesh.tets.push_back(t);
      }
    } else {
      const int arity = skipped_arity(keyword);
      if (arity < 0) tok.fail("unknown keyword '" + std::string(raw.substr(0, 40)) + "'");
      const std::size_t n =
          read_count(tok, std::string(raw), max_count / static_cast<std::size_t>(arity));
      for (std::size_t i = 0; i < n * static_cast<std::size_t>(arity); ++i) {
        double ignored = 0.0;
        const std::string_view token = tok.next("section data");
        if (!parse_double(token, ignored))
          tok.fail("expected a number in " + std::string(raw) + ", got '" +
                   std::string(token.substr(0, 40)) + "'");
      }
    }
  }
  if (!saw_dimension && mesh.nodes.empty())
    throw InputError(path, "not a MEDIT mesh (no Dimension, no Vertices)");
  for (const auto& [tet, line] : pending_tets)
    for (std::uint32_t v : mesh.tets[tet])
      if (v >= mesh.nodes.size())
        tok.fail_at(line, "vertex index " + std::to_string(std::uint64_t{v} + 1) +
                              " out of range (" + std::to_string(mesh.nodes.size()) + " vertices)");
  return mesh;
}

void write_medit(const std::string& path, const TetMesh& mesh) {
  std::string out;
  out.reserve(64 + mesh.nodes.size() * 64 + mesh.tets.size() * 40);
  out += "MeshVersionFormatted 2\nDimension 3\nVertices\n";
  append_uint(out, mesh.nodes.size());
  out += '\n';
  for (const Vec3& p : mesh.nodes) {
    append_point(out, p);
    out += " 0\n";
  }
  out += "Tetrahedra\n";
  append_uint(out, mesh.tets.size());
  out += '\n';
  for (const Tet& t : mesh.tets) {
    for (std::uint32_t v : t) {
      append_uint(out, std::uint64_t{v} + 1);
      out += ' ';
    }
    out += "1\n";
  }
  out += "End\n";
  write_text_file(path, out);
}

}  // namespace tetseg::preprocess::detail
