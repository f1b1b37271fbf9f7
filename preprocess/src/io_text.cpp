// Shared text I/O helpers and the format dispatch of read_tet_mesh / write_tet_mesh.

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>

#include "io_text.hpp"
#include "tetseg/preprocess/io.hpp"
#include "vec3_math.hpp"

namespace tetseg::preprocess {
namespace detail {

std::string read_file_text(const std::string& path) {
  // One read into a buffer of the file's size (no stream copies); read until end of file in
  // case the size changes meanwhile or is unknown (pipes).
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> owner(std::fopen(path.c_str(), "rb"),
                                                              &std::fclose);
  std::FILE* file = owner.get();
  if (file == nullptr) throw InputError(path, "cannot open file");
  std::string text;
  struct stat status {};
  if (::fstat(::fileno(file), &status) == 0 && S_ISREG(status.st_mode) && status.st_size > 0)
    text.reserve(static_cast<std::size_t>(status.st_size) + 1);
  char chunk[1 << 16];
  std::size_t got = 0;
  while (true) {
    const std::size_t used = text.size();
    if (text.capacity() > used + sizeof chunk) {
      // Read straight into the reserved space.
      text.resize(text.capacity());
      got = std::fread(text.data() + used, 1, text.size() - used, file);
      text.resize(used + got);
    } else {
      got = std::fread(chunk, 1, sizeof chunk, file);
      text.append(chunk, got);
    }
    if (got == 0) break;
  }
  if (std::ferror(file) != 0) throw InputError(path, "cannot read file");
  return text;
}

namespace {
/// std::isspace in the "C" locale, inline.
bool is_space(char c) {
  return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
}  // namespace

Tokenizer::Tokenizer(std::string file, std::string_view text, char comment)
    : m_file(std::move(file)), m_text(text), m_comment(comment) {}

void Tokenizer::skip_space(bool stop_at_newline) {
  while (m_pos < m_text.size()) {
    const char c = m_text[m_pos];
    if (c == '\n') {
      if (stop_at_newline) return;
      ++m_line;
      ++m_pos;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++m_pos;
    } else if (m_comment != '\0' && c == m_comment) {
      while (m_pos < m_text.size() && m_text[m_pos] != '\n') ++m_pos;
    } else {
      return;
    }
  }
}

std::string_view Tokenizer::next_or_end() {
  skip_space(false);
  if (m_pos >= m_text.size()) {
    m_token_line = m_line;
    return {};
  }
  const std::size_t begin = m_pos;
  while (m_pos < m_text.size()) {
    const char c = m_text[m_pos];
    if (is_space(c) || (m_comment != '\0' && c == m_comment)) break;
    ++m_pos;
  }
  m_token_line = m_line;
  return m_text.substr(begin, m_pos - begin);
}

std::string_view Tokenizer::next(const char* what) {
  const std::string_view token = next_or_end();
  if (token.empty()) fail(std::string("unexpected end of file (expected ") + what + ")");
  return token;
}

std::vector<std::string_view> Tokenizer::rest_of_line() {
  std::vector<std::string_view> tokens;
  rest_of_line(tokens);
  return tokens;
}

void Tokenizer::rest_of_line(std::vector<std::string_view>& tokens) {
  tokens.clear();
  for (;;) {
    skip_space(true);
    if (m_pos >= m_text.size()) break;
    if (m_text[m_pos] == '\n') {
      ++m_pos;
      ++m_line;
      break;
    }
    const std::size_t begin = m_pos;
    while (m_pos < m_text.size()) {
      const char c = m_text[m_pos];
      if (is_space(c) || (m_comment != '\0' && c == m_comment)) break;
      ++m_pos;
    }
    tokens.push_back(m_text.substr(begin, m_pos - begin));
  }
}

bool Tokenizer::next_record(std::vector<std::string_view>& tokens, std::size_t& line) {
  while (!at_end()) {
    line = m_line;
    rest_of_line(tokens);
    if (!tokens.empty()) {
      m_token_line = line;
      return true;
    }
  }
  tokens.clear();
  line = m_line;
  m_token_line = line;
  return false;
}

bool Tokenizer::at_end() {
  skip_space(false);
  return m_pos >= m_text.size();
}

double Tokenizer::next_double(const char* what) {
  const std::string_view token = next(what);
  double value = 0.0;
  if (!parse_double(token, value))
    fail(std::string("expected ") + what + ", got '" + std::string(token.substr(0, 40)) + "'");
  if (!std::isfinite(value)) fail(std::string(what) + " is not finite");
  return value;
}

std::int64_t Tokenizer::next_int(const char* what) {
  const std::string_view token = next(what);
  std::int64_t value = 0;
  if (!parse_int(token, value))
    fail(std::string("expected ") + what + ", got '" + std::string(token.substr(0, 40)) + "'");
  return value;
}

void Tokenizer::fail(const std::string& message) const {
  fail_at(m_token_line, message);
}

void Tokenizer::fail_at(std::size_t line, const std::string& message) const {
  throw InputError(m_file, "line " + std::to_string(line) + ": " + message);
}

bool parse_double(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ec == std::errc::result_out_of_range) {
    // Over/underflow: fall back to strtod, which gives inf or 0 (callers check finiteness).
    char buffer[72];
    if (token.size() >= sizeof buffer) return false;
    std::copy(token.begin(), token.end(), buffer);
    buffer[token.size()] = '\0';
    value = std::strtod(buffer, nullptr);
    return ptr == end;
  }
  return ec == std::errc() && ptr == end;
}

bool parse_int(std::string_view token, std::int64_t& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

void append_double(std::string& out, double value) {
  // Shortest representation that reads back to the same double.
  char buffer[40];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, static_cast<std::size_t>(ptr - buffer));
}

void append_point(std::string& out, const Vec3& p) {
  append_double(out, p[0]);
  out += ' ';
  append_double(out, p[1]);
  out += ' ';
  append_double(out, p[2]);
}

void append_uint(std::string& out, std::uint64_t value) {
  char buffer[24];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, static_cast<std::size_t>(ptr - buffer));
}

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

std::pair<Vec3, Vec3> bounding_box(const std::vector<Vec3>& points) {
  Vec3 lo = {0, 0, 0};
  Vec3 hi = {0, 0, 0};
  if (!points.empty()) lo = hi = points.front();
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  return {lo, hi};
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw OutputError(path, "cannot open file for writing");
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.flush();
  if (!out) throw OutputError(path, "write failed");
}

std::string lower_extension(const std::string& path) {
  const std::size_t slash = path.find_last_of("/\\");
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

void orient_consistently_negative_meshes(TetMesh& mesh) {
  std::size_t negative = 0;
  std::size_t positive = 0;
  std::size_t out_of_range = 0;
  const std::int64_t tet_count = static_cast<std::int64_t>(mesh.tets.size());
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(static) reduction(+ : negative, positive, out_of_range)
#endif
  for (std::int64_t i = 0; i < tet_count; ++i) {
    const Tet& t = mesh.tets[static_cast<std::size_t>(i)];
    if (t[0] >= mesh.nodes.size() || t[1] >= mesh.nodes.size() || t[2] >= mesh.nodes.size() ||
        t[3] >= mesh.nodes.size()) {
      ++out_of_range;
      continue;
    }
    const Vec3& a = mesh.nodes[t[0]];
    const Vec3& b = mesh.nodes[t[1]];
    const Vec3& c = mesh.nodes[t[2]];
    const Vec3& d = mesh.nodes[t[3]];
    const double det = tet_det(a, b, c, d);
    if (det > 0) ++positive;
    if (det < 0) ++negative;
  }
  if (out_of_range == 0 && positive == 0 && negative > 0)
    for (Tet& t : mesh.tets) std::swap(t[2], t[3]);
}

}  // namespace detail

bool is_tet_mesh_path(const std::string& path) {
  const std::string ext = detail::lower_extension(path);
  return ext == ".mesh" || ext == ".node" || ext == ".ele" || ext == ".msh";
}

TetMesh read_tet_mesh(const std::string& path) {
  const std::string ext = detail::lower_extension(path);
  TetMesh mesh;
  if (ext == ".mesh") {
    mesh = detail::read_medit(path);
  } else if (ext == ".node" || ext == ".ele") {
    mesh = detail::read_tetgen(path);
  } else if (ext == ".msh") {
    mesh = detail::read_gmsh(path);
  } else {
    throw InputError(path,
                     "unknown tet mesh format '" + ext + "' (expected .mesh, .node/.ele or .msh)");
  }
  if (mesh.tets.empty()) throw InputError(path, "no tetrahedra in file");
  detail::orient_consistently_negative_meshes(mesh);
  return mesh;
}

void write_tet_mesh(const std::string& path, const TetMesh& mesh) {
  const std::string ext = detail::lower_extension(path);
  if (ext == ".mesh") {
    detail::write_medit(path, mesh);
  } else if (ext == ".node" || ext == ".ele") {
    detail::write_tetgen(path, mesh);
  } else if (ext == ".msh") {
    detail::write_gmsh41(path, mesh);
  } else {
    throw OutputError(path,
                      "unknown tet mesh format '" + ext + "' (expected .mesh, .node/.ele or .msh)");
  }
}

void write_gmsh22(const std::string& path, const TetMesh& mesh) {
  detail::write_gmsh22_impl(path, mesh);
}

void write_gmsh41_binary(const std::string& path, const TetMesh& mesh) {
  detail::write_gmsh41_binary_impl(path, mesh);
}

}  // namespace tetseg::preprocess
