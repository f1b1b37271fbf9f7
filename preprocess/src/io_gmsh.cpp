// Gmsh .msh 2.2 and 4.1 ASCII reader and writers (binary: io_gmsh_binary.cpp).

#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

#include "io_text.hpp"

namespace tetseg::preprocess::detail {
namespace {

constexpr std::int64_t kGmshTet4 = 4;
constexpr std::int64_t kGmshTet10 = 11;

struct GmshState {
  int major = 0;
  std::unordered_map<std::int64_t, std::uint32_t> node_of_tag;
  std::vector<std::size_t> tet_lines;
};

void expect_token(Tokenizer& tok, const char* expected) {
  const std::string_view token = tok.next(expected);
  if (token != expected)
    tok.fail(std::string("expected ") + expected + ", got '" + std::string(token.substr(0, 40)) +
             "'");
}

std::int64_t count_field(Tokenizer& tok, const char* what, std::size_t limit) {
  const std::int64_t n = tok.next_int(what);
  if (n < 0 || static_cast<std::uint64_t>(n) > limit)
    tok.fail(std::string("invalid ") + what + " " + std::to_string(n));
  return n;
}

void add_node(Tokenizer& tok, GmshState& state, TetMesh& mesh, std::int64_t tag, const Vec3& p,
              std::size_t line) {
  const auto [it, inserted] =
      state.node_of_tag.emplace(tag, static_cast<std::uint32_t>(mesh.nodes.size()));
  if (!inserted) tok.fail_at(line, "duplicate node tag " + std::to_string(tag));
  mesh.nodes.push_back(p);
}

void add_tet(Tokenizer& tok, GmshState& state, TetMesh& mesh,
             const std::vector<std::string_view>& node_tokens, std::size_t line) {
  Tet t;
  for (std::size_t k = 0; k < 4; ++k) {
    std::int64_t tag = 0;
    if (!parse_int(node_tokens[k], tag))
      tok.fail_at(line,
                  "expected a node tag, got '" + std::string(node_tokens[k].substr(0, 40)) + "'");
    const auto it = state.node_of_tag.find(tag);
    if (it == state.node_of_tag.end())
      tok.fail_at(line, "node tag " + std::to_string(tag) + " out of range (no such node)");
    t[k] = it->second;
  }
  mesh.tets.push_back(t);
}

void read_nodes_v2(Tokenizer& tok, GmshState& state, TetMesh& mesh, std::size_t limit) {
  const std::int64_t n = count_field(tok, "node count", limit);
  mesh.nodes.reserve(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t tag = tok.next_int("a node tag");
    const std::size_t line = tok.line();
    Vec3 p;
    p[0] = tok.next_double("a node coordinate");
    p[1] = tok.next_double("a node coordinate");
    p[2] = tok.next_double("a node coordinate");
    add_node(tok, state, mesh, tag, p, line);
  }
}

void read_nodes_v41(Tokenizer& tok, GmshState& state, TetMesh& mesh, std::size_t limit) {
  const std::int64_t blocks = count_field(tok, "node block count", limit);
  const std::int64_t n = count_field(tok, "node count", limit);
  tok.next_int("a minimum node tag");
  tok.next_int("a maximum node tag");
  mesh.nodes.reserve(static_cast<std::size_t>(n));
  std::int64_t total = 0;
  std::vector<std::int64_t> tags;
  std::vector<std::size_t> lines;
  for (std::int64_t b = 0; b < blocks; ++b) {
    const std::int64_t dim = tok.next_int("an entity dimension");
    tok.next_int("an entity tag");
    const std::int64_t parametric = tok.next_int("a parametric flag");
    const std::int64_t count = count_field(tok, "node count of a block", limit);
    if (dim < 0 || dim > 3) tok.fail("invalid entity dimension " + std::to_string(dim));
    if (parametric != 0 && parametric != 1) tok.fail("parametric flag must be 0 or 1");
    total += count;
    if (total > n)
      tok.fail("node blocks hold more nodes than the header's count " + std::to_string(n));
    tags.resize(static_cast<std::size_t>(count));
    lines.resize(static_cast<std::size_t>(count));
    for (std::int64_t i = 0; i < count; ++i) {
      tags[static_cast<std::size_t>(i)] = tok.next_int("a node tag");
      lines[static_cast<std::size_t>(i)] = tok.line();
    }
    const int extra = parametric == 1 ? static_cast<int>(dim) : 0;
    for (std::int64_t i = 0; i < count; ++i) {
      Vec3 p;
      p[0] = tok.next_double("a node coordinate");
      p[1] = tok.next_double("a node coordinate");
      p[2] = tok.next_double("a node coordinate");
      for (int e = 0; e < extra; ++e) tok.next_double("a parametric coordinate");
      add_node(tok, state, mesh, tags[static_cast<std::size_t>(i)], p, tok.line());
    }
  }
  if (total != n)
    tok.fail("node blocks hold " + std::to_string(total) + " nodes, header says " +
             std::to_string(n));
}

void read_elements_v2(Tokenizer& tok, GmshState& state, TetMesh& mesh, std::size_t limit) {
  const std::int64_t n = count_field(tok, "element count", limit);
  tok.rest_of_line();
  std::vector<std::string_view> f;
  std::size_t line = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    if (!tok.next_record(f, line))
      tok.fail_at(line,
                  "unexpected end of file (expected " + std::to_string(n - i) + " more elements)");
    if (f.size() < 3) tok.fail_at(line, "element line too short");
    std::int64_t type = 0;
    std::int64_t ntags = 0;
    if (!parse_int(f[1], type) || !parse_int(f[2], ntags) || ntags < 0 ||
        static_cast<std::size_t>(ntags) + 3 > f.size())
      tok.fail_at(line, "malformed element line");
    if (type == kGmshTet4 || type == kGmshTet10) {
      const std::size_t first = 3 + static_cast<std::size_t>(ntags);
      const std::size_t expected = type == kGmshTet4 ? 4 : 10;
      if (f.size() - first != expected)
        tok.fail_at(line, "tetrahedron needs " + std::to_string(expected) + " nodes, got " +
                              std::to_string(f.size() - first));
      add_tet(
          tok, state, mesh,
          std::vector<std::string_view>(f.begin() + static_cast<std::ptrdiff_t>(first), f.end()),
          line);
    }
  }
}

void read_elements_v41(Tokenizer& tok, GmshState& state, TetMesh& mesh, std::size_t limit) {
  const std::int64_t blocks = count_field(tok, "element block count", limit);
  const std::int64_t n = count_field(tok, "element count", limit);
  tok.next_int("a minimum element tag");
  tok.next_int("a maximum element tag");
  std::int64_t total = 0;
  std::vector<std::string_view> f;
  std::size_t line = 0;
  for (std::int64_t b = 0; b < blocks; ++b) {
    tok.next_int("an entity dimension");
    tok.next_int("an entity tag");
    const std::int64_t type = tok.next_int("an element type");
    const std::int64_t count = count_field(tok, "element count of a block", limit);
    total += count;
    if (total > n)
      tok.fail("element blocks hold more elements than the header's count " + std::to_string(n));
    if (!tok.rest_of_line().empty()) tok.fail("unexpected values after an element block header");
    for (std::int64_t i = 0; i < count; ++i) {
      if (!tok.next_record(f, line))
        tok.fail_at(line, "unexpected end of file (expected " + std::to_string(count - i) +
                              " more elements in the block)");
      if (type == kGmshTet4 || type == kGmshTet10) {
        const std::size_t expected = type == kGmshTet4 ? 5 : 11;
        if (f.size() != expected)
          tok.fail_at(line, "tetrahedron line needs " + std::to_string(expected) + " values, got " +
                                std::to_string(f.size()));
        add_tet(tok, state, mesh, std::vector<std::string_view>(f.begin() + 1, f.end()), line);
      }
    }
  }
  if (total != n)
    tok.fail("element blocks hold " + std::to_string(total) + " elements, header says " +
             std::to_string(n));
}

void skip_section(Tokenizer& tok, std::string_view name) {
  const std::string end = "$End" + std::string(name.substr(1));
  const std::size_t start = tok.line();
  for (;;) {
    const std::string_view token = tok.next_or_end();
    if (token.empty())
      tok.fail_at(start,
                  "unexpected end of file (section " + std::string(name) + " has no " + end + ")");
    if (token == end) return;
  }
}

}  // namespace

TetMesh read_gmsh(const std::string& path) {
  const std::string text = read_file_text(path);
  Tokenizer tok(path, text, '\0');
  GmshState state;
  TetMesh mesh;
  const std::size_t limit = text.size() / 2 + 1;
  bool saw_nodes = false;
  for (;;) {
    const std::string_view section = tok.next_or_end();
    if (section.empty()) break;
    if (section.size() < 2 || section[0] != '$')
      tok.fail("expected a $Section, got '" + std::string(section.substr(0, 40)) + "'");
    if (section == "$MeshFormat") {
      const std::string_view version = tok.next("a format version");
      const std::int64_t file_type = tok.next_int("a file type");
      const std::int64_t data_size = tok.next_int("a data size");
      if (version == "2" || version == "2.0" || version == "2.1" || version == "2.2") {
        state.major = 2;
      } else if (version == "4.1") {
        state.major = 4;
      } else {
        tok.fail("unsupported Gmsh version " + std::string(version.substr(0, 20)) +
                 " (2.2 and 4.1 are supported)");
      }
      if (file_type == 1)
        return read_gmsh_binary(path, text, tok.position(), state.major, data_size);
      if (file_type != 0) tok.fail("file type must be 0 (ASCII) or 1 (binary)");
      expect_token(tok, "$EndMeshFormat");
      continue;
    }
    if (state.major == 0)
      tok.fail("missing $MeshFormat before " + std::string(section.substr(0, 40)));
    if (section == "$Nodes") {
      if (saw_nodes) tok.fail("second $Nodes section");
      saw_nodes = true;
      if (state.major == 2) {
        read_nodes_v2(tok, state, mesh, limit);
      } else {
        read_nodes_v41(tok, state, mesh, limit);
      }
      expect_token(tok, "$EndNodes");
    } else if (section == "$Elements") {
      if (!saw_nodes) tok.fail("$Elements before $Nodes");
      if (state.major == 2) {
        read_elements_v2(tok, state, mesh, limit);
      } else {
        read_elements_v41(tok, state, mesh, limit);
      }
      expect_token(tok, "$EndElements");
    } else {
      skip_section(tok, section);
    }
  }
  if (state.major == 0) throw InputError(path, "not a Gmsh file (no $MeshFormat)");
  return mesh;
}

void write_gmsh41(const std::string& path, const TetMesh& mesh) {
  const auto [lo, hi] = bounding_box(mesh.nodes);
  std::string out;
  out.reserve(256 + mesh.nodes.size() * 64 + mesh.tets.size() * 48);
  out += "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1";
  out += ' ';
  append_point(out, lo);
  out += ' ';
  append_point(out, hi);
  out += " 0 0\n$EndEntities\n$Nodes\n";
  const std::size_t n = mesh.nodes.size();
  out += "1 ";
  append_uint(out, n);
  out += n > 0 ? " 1 " : " 0 ";
  append_uint(out, n);
  out += "\n3 1 0 ";
  append_uint(out, n);
  out += '\n';
  for (std::size_t i = 0; i < n; ++i) {
    append_uint(out, i + 1);
    out += '\n';
  }
  for (const Vec3& p : mesh.nodes) {
    append_point(out, p);
    out += '\n';
  }
  out += "$EndNodes\n$Elements\n1 ";
  const std::size_t m = mesh.tets.size();
  append_uint(out, m);
  out += m > 0 ? " 1 " : " 0 ";
  append_uint(out, m);
  out += "\n3 1 4 ";
  append_uint(out, m);
  out += '\n';
  for (std::size_t i = 0; i < m; ++i) {
    append_uint(out, i + 1);
    for (std::uint32_t v : mesh.tets[i]) {
      out += ' ';
      append_uint(out, std::uint64_t{v} + 1);
    }
    out += '\n';
  }
  out += "$EndElements\n";
  write_text_file(path, out);
}

void write_gmsh22_impl(const std::string& path, const TetMesh& mesh) {
  std::string out;
  out.reserve(128 + mesh.nodes.size() * 64 + mesh.tets.size() * 48);
  out += "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n";
  append_uint(out, mesh.nodes.size());
  out += '\n';
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    append_uint(out, i + 1);
    out += ' ';
    append_point(out, mesh.nodes[i]);
    out += '\n';
  }
  out += "$EndNodes\n$Elements\n";
  append_uint(out, mesh.tets.size());
  out += '\n';
  for (std::size_t i = 0; i < mesh.tets.size(); ++i) {
    append_uint(out, i + 1);
    out += " 4 2 0 1";
    for (std::uint32_t v : mesh.tets[i]) {
      out += ' ';
      append_uint(out, std::uint64_t{v} + 1);
    }
    out += '\n';
  }
  out += "$EndElements\n";
  write_text_file(path, out);
}

}  // namespace tetseg::preprocess::detail
