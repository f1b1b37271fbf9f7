// TetGen .node + .ele reader and writer.

#include <cmath>
#include <string>
#include <vector>

#include "io_text.hpp"

namespace tetseg::preprocess::detail {
namespace {

std::string stem_of(const std::string& path) {
  const std::string ext = lower_extension(path);
  return path.substr(0, path.size() - ext.size());
}

std::int64_t int_field(const Tokenizer& tok, std::string_view token, std::size_t line,
                       const char* what) {
  std::int64_t value = 0;
  if (!parse_int(token, value))
    tok.fail_at(
        line, std::string("expected ") + what + ", got '" + std::string(token.substr(0, 40)) + "'");
  return value;
}

double double_field(const Tokenizer& tok, std::string_view token, std::size_t line,
                    const char* what) {
  double value = 0.0;
  if (!parse_double(token, value))
    tok.fail_at(
        line, std::string("expected ") + what + ", got '" + std::string(token.substr(0, 40)) + "'");
  if (!std::isfinite(value)) tok.fail_at(line, std::string(what) + " is not finite");
  return value;
}

void require_record(Tokenizer& tok, std::vector<std::string_view>& tokens, std::size_t& line,
                    const std::string& what) {
  if (!tok.next_record(tokens, line))
    tok.fail_at(line, "unexpected end of file (expected " + what + ")");
}

}  // namespace

TetMesh read_tetgen(const std::string& path) {
  const std::string stem = stem_of(path);
  const std::string node_path = stem + ".node";
  const std::string ele_path = stem + ".ele";
  TetMesh mesh;
  std::int64_t base = 0;
  {
    const std::string text = read_file_text(node_path);
    Tokenizer tok(node_path, text, '#');
    std::vector<std::string_view> f;
    std::size_t line = 1;
    require_record(tok, f, line, "the .node header");
    if (f.size() < 1 || f.size() > 4)
      tok.fail_at(line, "header must be '<#points> <dim> <#attributes> <boundary marker>'");
    const std::int64_t n = int_field(tok, f[0], line, "a point count");
    const std::int64_t dim = f.size() > 1 ? int_field(tok, f[1], line, "a dimension") : 3;
    const std::int64_t attrs = f.size() > 2 ? int_field(tok, f[2], line, "an attribute count") : 0;
    const std::int64_t marker = f.size() > 3 ? int_field(tok, f[3], line, "a marker flag") : 0;
    if (dim != 3) tok.fail_at(line, "dimension " + std::to_string(dim) + " is not 3");
    if (n < 0 || static_cast<std::uint64_t>(n) > text.size() / 4 + 1)
      tok.fail_at(line, "invalid point count " + std::to_string(n));
    if (attrs < 0 || attrs > 1000)
      tok.fail_at(line, "invalid attribute count " + std::to_string(attrs));
    if (marker != 0 && marker != 1) tok.fail_at(line, "boundary marker flag must be 0 or 1");
    const std::size_t fields = static_cast<std::size_t>(4 + attrs + marker);
    mesh.nodes.reserve(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) {
      require_record(tok, f, line, std::to_string(n - i) + " more point" + (n - i == 1 ? "" : "s"));
      if (f.size() != fields)
        tok.fail_at(line, "expected " + std::to_string(fields) + " values, got " +
                              std::to_string(f.size()));
      const std::int64_t index = int_field(tok, f[0], line, "a point index");
      if (i == 0) {
        if (index != 0 && index != 1) tok.fail_at(line, "first point index must be 0 or 1");
        base = index;
      } else if (index != base + i) {
        tok.fail_at(line, "point index " + std::to_string(index) + " out of sequence (expected " +
                              std::to_string(base + i) + ")");
      }
      mesh.nodes.push_back({double_field(tok, f[1], line, "a coordinate"),
                            double_field(tok, f[2], line, "a coordinate"),
                            double_field(tok, f[3], line, "a coordinate")});
    }
    if (tok.next_record(f, line))
      tok.fail_at(line, "more points than the header's count " + std::to_string(n));
  }
  {
    const std::string text = read_file_text(ele_path);
    Tokenizer tok(ele_path, text, '#');
    std::vector<std::string_view> f;
    std::size_t line = 1;
    require_record(tok, f, line, "the .ele header");
    if (f.size() < 2 || f.size() > 3)
      tok.fail_at(line, "header must be '<#tetrahedra> <nodes per tetrahedron> <#attributes>'");
    const std::int64_t n = int_field(tok, f[0], line, "a tetrahedron count");
    const std::int64_t per = int_field(tok, f[1], line, "a node count per tetrahedron");
    const std::int64_t attrs = f.size() > 2 ? int_field(tok, f[2], line, "an attribute count") : 0;
    if (n < 0 || static_cast<std::uint64_t>(n) > text.size() / 5 + 1)
      tok.fail_at(line, "invalid tetrahedron count " + std::to_string(n));
    if (per != 4 && per != 10) tok.fail_at(line, "nodes per tetrahedron must be 4 or 10");
    if (attrs < 0 || attrs > 1000)
      tok.fail_at(line, "invalid attribute count " + std::to_string(attrs));
    const std::size_t fields = static_cast<std::size_t>(1 + per + attrs);
    mesh.tets.reserve(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i) {
      require_record(tok, f, line,
                     std::to_string(n - i) + " more tetrahedr" + (n - i == 1 ? "on" : "a"));
      if (f.size() != fields)
        tok.fail_at(line, "expected " + std::to_string(fields) + " values, got " +
                              std::to_string(f.size()));
      const std::int64_t index = int_field(tok, f[0], line, "a tetrahedron index");
      if (index != base + i)
        tok.fail_at(line, "tetrahedron index " + std::to_string(index) +
                              " out of sequence (expected " + std::to_string(base + i) + ")");
      Tet t;
      for (std::size_t k = 0; k < 4; ++k) {
        const std::int64_t v = int_field(tok, f[1 + k], line, "a point index");
        if (v < base || v - base >= static_cast<std::int64_t>(mesh.nodes.size()))
          tok.fail_at(
              line,
              "point index " + std::to_string(v) + " out of range (" + std::to_string(base) + ".." +
                  std::to_string(base + static_cast<std::int64_t>(mesh.nodes.size()) - 1) + ")");
        t[k] = static_cast<std::uint32_t>(v - base);
      }
      mesh.tets.push_back(t);
    }
    if (tok.next_record(f, line))
      tok.fail_at(line, "more tetrahedra than the header's count " + std::to_string(n));
  }
  return mesh;
}

void write_tetgen(const std::string& path, const TetMesh& mesh) {
  const std::string stem = stem_of(path);
  std::string out;
  out.reserve(32 + mesh.nodes.size() * 64);
  append_uint(out, mesh.nodes.size());
  out += " 3 0 0\n";
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    append_uint(out, i);
    out += ' ';
    append_point(out, mesh.nodes[i]);
    out += '\n';
  }
  write_text_file(stem + ".node", out);
  out.clear();
  append_uint(out, mesh.tets.size());
  out += " 4 0\n";
  for (std::size_t i = 0; i < mesh.tets.size(); ++i) {
    append_uint(out, i);
    for (std::uint32_t v : mesh.tets[i]) {
      out += ' ';
      append_uint(out, v);
    }
    out += '\n';
  }
  write_text_file(stem + ".ele", out);
}

}  // namespace tetseg::preprocess::detail
