// Binary Gmsh .msh 2.2 and 4.1: reader (after io_gmsh.cpp has read the $MeshFormat line) and
// the binary 4.1 writer. Every count is checked against the bytes left before anything is
// reserved or read; errors name the byte offset.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "io_text.hpp"

namespace tetseg::preprocess::detail {
namespace {

constexpr int kGmshTet4 = 4;
constexpr int kGmshTet10 = 11;

/// Nodes per element type (Gmsh's numbering; 0: unknown). Needed to step over other elements.
std::uint64_t nodes_of_type(std::int64_t type) {
  static const std::uint64_t kNodes[] = {0,  2,  3,  4,  4, 8, 6,  5,  3,  6, 9,
                                         10, 27, 18, 14, 1, 8, 20, 15, 13, 9, 10,
                                         12, 15, 15, 21, 4, 5, 6,  20, 35, 56};
  if (type >= 1 && type < static_cast<std::int64_t>(sizeof kNodes / sizeof kNodes[0]))
    return kNodes[type];
  if (type == 92) return 64;
  if (type == 93) return 125;
  return 0;
}

/// Reads little- or big-endian scalars and ASCII words from the binary file.
class ByteReader {
 public:
  ByteReader(const std::string& file, std::string_view bytes, std::size_t pos)
      : m_file(file), m_bytes(bytes), m_pos(pos) {}

  std::size_t left() const { return m_bytes.size() - m_pos; }
  void set_swap(bool swap) { m_swap = swap; }

  [[noreturn]] void fail(const std::string& message) const {
    throw InputError(m_file, "byte " + std::to_string(m_pos) + ": " + message);
  }

  /// Fails unless `count` items of `item_bytes` each remain.
  void need(std::uint64_t count, std::uint64_t item_bytes, const char* what) const {
    if (item_bytes != 0 && count > left() / item_bytes)
      fail(std::string(what) + " count " + std::to_string(count) +
           " exceeds the bytes left in the file (" + std::to_string(left()) + ")");
  }

  template <class T>
  T scalar(const char* what) {
    if (left() < sizeof(T)) fail(std::string("unexpected end of file (") + what + ")");
    unsigned char raw[sizeof(T)];
    std::memcpy(raw, m_bytes.data() + m_pos, sizeof(T));
    if (m_swap) std::reverse(raw, raw + sizeof(T));
    T value;
    std::memcpy(&value, raw, sizeof(T));
    m_pos += sizeof(T);
    return value;
  }

  std::int64_t int32(const char* what) { return scalar<std::int32_t>(what); }

  /// A size_t field of the file's data size (4 or 8 bytes).
  std::uint64_t size_field(std::int64_t data_size, const char* what) {
    return data_size == 4 ? scalar<std::uint32_t>(what) : scalar<std::uint64_t>(what);
  }

  double coordinate() {
    const double value = scalar<double>("a node coordinate");
    if (!std::isfinite(value)) fail("node coordinate is not finite");
    return value;
  }

  /// Skips whitespace, then returns the next run of non-space bytes ("" at the end).
  std::string_view word() {
    skip_space();
    const std::size_t start = m_pos;
    while (m_pos < m_bytes.size() && !is_space(m_bytes[m_pos])) ++m_pos;
    return m_bytes.substr(start, m_pos - start);
  }

  /// Consumes the one line break that separates an ASCII field from binary data.
  void line_break() {
    if (m_pos < m_bytes.size() && m_bytes[m_pos] == '\r') ++m_pos;
    if (m_pos >= m_bytes.size() || m_bytes[m_pos] != '\n') fail("expected a line break");
    ++m_pos;
  }

  void expect(std::string_view marker) {
    const std::string_view got = word();
    if (got != marker)
      fail("expected " + std::string(marker) + ", got '" + std::string(got.substr(0, 40)) + "'");
  }

  /// Steps past "$EndName" for a section this reader does not use.
  void skip_section(std::string_view name) {
    const std::string end = "$End" + std::string(name.substr(1));
    const std::size_t found = m_bytes.find(end, m_pos);
    if (found == std::string_view::npos)
      fail("unexpected end of file (section " + std::string(name) + " has no " + end + ")");
    m_pos = found + end.size();
  }

  std::int64_t ascii_count(const char* what) {
    const std::string_view token = word();
    std::int64_t n = 0;
    if (!parse_int(token, n) || n < 0)
      fail(std::string("invalid ") + what + " '" + std::string(token.substr(0, 40)) + "'");
    line_break();
    return n;
  }

 private:
  static bool is_space(char c) {
    return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v';
  }
  void skip_space() {
    while (m_pos < m_bytes.size() && is_space(m_bytes[m_pos])) ++m_pos;
  }

  const std::string& m_file;
  std::string_view m_bytes;
  std::size_t m_pos;
  bool m_swap = false;
};

struct BinaryGmsh {
  ByteReader& in;
  TetMesh& mesh;
  std::int64_t data_size;
  std::unordered_map<std::uint64_t, std::uint32_t> node_of_tag;

  void add_node(std::uint64_t tag, const Vec3& p) {
    if (!node_of_tag.emplace(tag, static_cast<std::uint32_t>(mesh.nodes.size())).second)
      in.fail("duplicate node tag " + std::to_string(tag));
    mesh.nodes.push_back(p);
  }

  std::uint32_t node(std::uint64_t tag) const {
    const auto it = node_of_tag.find(tag);
    if (it == node_of_tag.end())
      in.fail("node tag " + std::to_string(tag) + " out of range (no such node)");
    return it->second;
  }

  void nodes_v2() {
    const auto n = static_cast<std::uint64_t>(in.ascii_count("node count"));
    in.need(n, 4 + 3 * 8, "node");
    mesh.nodes.reserve(n);
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::int64_t tag = in.int32("a node tag");
      const Vec3 p = {in.coordinate(), in.coordinate(), in.coordinate()};
      add_node(static_cast<std::uint64_t>(tag), p);
    }
  }

  void elements_v2() {
    const auto n = static_cast<std::uint64_t>(in.ascii_count("element count"));
    std::uint64_t read = 0;
    while (read < n) {
      const std::int64_t type = in.int32("an element type");
      const std::int64_t count = in.int32("an element count");
      const std::int64_t tags = in.int32("a tag count");
      const std::uint64_t nodes = nodes_of_type(type);
      if (nodes == 0) in.fail("unknown element type " + std::to_string(type));
      if (count <= 0 || tags < 0 || static_cast<std::uint64_t>(count) > n - read)
        in.fail("invalid element block (" + std::to_string(count) + " elements, " +
                std::to_string(tags) + " tags)");
      const std::uint64_t ints = 1 + static_cast<std::uint64_t>(tags) + nodes;
      in.need(static_cast<std::uint64_t>(count), 4 * ints, "element");
      for (std::int64_t e = 0; e < count; ++e) {
        in.int32("an element number");
        for (std::int64_t t = 0; t < tags; ++t) in.int32("an element tag");
        Tet tet{};
        for (std::uint64_t k = 0; k < nodes; ++k) {
          const std::int64_t tag = in.int32("a node tag");
          if ((type == kGmshTet4 || type == kGmshTet10) && k < 4)
            tet[k] = node(static_cast<std::uint64_t>(tag));
        }
        if (type == kGmshTet4 || type == kGmshTet10) mesh.tets.push_back(tet);
      }
      read += static_cast<std::uint64_t>(count);
    }
  }

  /// The line break after a 4.1 section keyword, then its four size fields: number of
  /// blocks, of items, minimum and maximum tag. Returns {blocks, items}; checks that the
  /// blocks' headers (three ints and a size each) fit in the bytes left.
  std::pair<std::uint64_t, std::uint64_t> section_header_v41(const char* blocks_what,
                                                             const char* items_what) {
    in.line_break();
    const std::uint64_t blocks = in.size_field(data_size, blocks_what);
    const std::uint64_t n = in.size_field(data_size, items_what);
    in.size_field(data_size, "the minimum tag");
    in.size_field(data_size, "the maximum tag");
    in.need(blocks, 12 + static_cast<std::uint64_t>(data_size), "block");
    return {blocks, n};
  }

  void nodes_v41() {
    const auto [blocks, n] = section_header_v41("the node block count", "the node count");
    const auto tag_bytes = static_cast<std::uint64_t>(data_size);
    in.need(n, tag_bytes + 24, "node");
    mesh.nodes.reserve(n);
    std::uint64_t total = 0;
    std::vector<std::uint64_t> tags;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      const std::int64_t dim = in.int32("an entity dimension");
      in.int32("an entity tag");
      const std::int64_t parametric = in.int32("a parametric flag");
      const std::uint64_t count = in.size_field(data_size, "the node count of a block");
      if (dim < 0 || dim > 3) in.fail("invalid entity dimension " + std::to_string(dim));
      if (parametric != 0 && parametric != 1) in.fail("parametric flag must be 0 or 1");
      if (count > n - total)
        in.fail("node blocks hold more nodes than the header's count " + std::to_string(n));
      total += count;
      const std::uint64_t values = 3 + (parametric == 1 ? static_cast<std::uint64_t>(dim) : 0);
      in.need(count, tag_bytes + 8 * values, "node");
      tags.resize(count);
      for (std::uint64_t& tag : tags) tag = in.size_field(data_size, "a node tag");
      for (std::uint64_t i = 0; i < count; ++i) {
        const Vec3 p = {in.coordinate(), in.coordinate(), in.coordinate()};
        for (std::uint64_t e = 3; e < values; ++e) in.scalar<double>("a parametric coordinate");
        add_node(tags[i], p);
      }
    }
    if (total != n)
      in.fail("node blocks hold " + std::to_string(total) + " nodes, header says " +
              std::to_string(n));
  }

  void elements_v41() {
    const auto [blocks, n] = section_header_v41("the element block count", "the element count");
    const auto tag_bytes = static_cast<std::uint64_t>(data_size);
    std::uint64_t total = 0;
    for (std::uint64_t b = 0; b < blocks; ++b) {
      in.int32("an entity dimension");
      in.int32("an entity tag");
      const std::int64_t type = in.int32("an element type");
      const std::uint64_t count = in.size_field(data_size, "the element count of a block");
      const std::uint64_t nodes = nodes_of_type(type);
      if (nodes == 0) in.fail("unknown element type " + std::to_string(type));
      if (count > n - total)
        in.fail("element blocks hold more elements than the header's count " + std::to_string(n));
      total += count;
      in.need(count, tag_bytes * (1 + nodes), "element");
      const bool tet = type == kGmshTet4 || type == kGmshTet10;
      if (tet) mesh.tets.reserve(mesh.tets.size() + count);
      for (std::uint64_t e = 0; e < count; ++e) {
        in.size_field(data_size, "an element tag");
        Tet t{};
        for (std::uint64_t k = 0; k < nodes; ++k) {
          const std::uint64_t tag = in.size_field(data_size, "a node tag");
          if (tet && k < 4) t[k] = node(tag);
        }
        if (tet) mesh.tets.push_back(t);
      }
    }
    if (total != n)
      in.fail("element blocks hold " + std::to_string(total) + " elements, header says " +
              std::to_string(n));
  }
};

void append_bytes(std::string& out, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const char*>(data);
  const std::size_t at = out.size();
  out.append(bytes, size);
  if (!host_is_little_endian())
    std::reverse(out.begin() + static_cast<std::ptrdiff_t>(at), out.end());
}

void append_int32(std::string& out, std::int32_t value) {
  append_bytes(out, &value, 4);
}
void append_size(std::string& out, std::uint64_t value) {
  append_bytes(out, &value, 8);
}
void append_f64(std::string& out, double value) {
  append_bytes(out, &value, 8);
}

/// A 4.1 $Nodes or $Elements section of one block on volume 1 holding `count` items tagged
/// 1..count: the section's four size fields, then the block's header (dimension 3, entity 1,
/// `kind` = parametric flag or element type, count).
void append_one_block_header(std::string& out, std::uint64_t count, std::int32_t kind) {
  append_size(out, 1);
  append_size(out, count);
  append_size(out, count > 0 ? 1 : 0);
  append_size(out, count);
  append_int32(out, 3);
  append_int32(out, 1);
  append_int32(out, kind);
  append_size(out, count);
}

}  // namespace

TetMesh read_gmsh_binary(const std::string& path, std::string_view text, std::size_t start,
                         int major, std::int64_t data_size) {
  ByteReader in(path, text, start);
  if (major == 2 && data_size != 8) in.fail("binary Gmsh 2 needs a data size of 8");
  if (major == 4 && data_size != 4 && data_size != 8)
    in.fail("binary Gmsh 4.1 needs a data size of 4 or 8, got " + std::to_string(data_size));
  // The format's endianness check: the integer 1, written in the writer's byte order.
  in.line_break();
  const std::int32_t one = in.scalar<std::int32_t>("the endianness check");
  if (one != 1) {
    std::int32_t swapped = one;
    unsigned char raw[4];
    std::memcpy(raw, &swapped, 4);
    std::reverse(raw, raw + 4);
    std::memcpy(&swapped, raw, 4);
    if (swapped != 1) in.fail("endianness check failed (expected the binary integer 1)");
    in.set_swap(true);
  }
  in.expect("$EndMeshFormat");
  TetMesh mesh;
  BinaryGmsh reader{in, mesh, data_size, {}};
  bool saw_nodes = false;
  for (;;) {
    const std::string_view section = in.word();
    if (section.empty()) break;
    if (section.size() < 2 || section[0] != '$')
      in.fail("expected a $Section, got '" + std::string(section.substr(0, 40)) + "'");
    if (section == "$Nodes") {
      if (saw_nodes) in.fail("second $Nodes section");
      saw_nodes = true;
      if (major == 2) {
        reader.nodes_v2();
      } else {
        reader.nodes_v41();
      }
      in.expect("$EndNodes");
    } else if (section == "$Elements") {
      if (!saw_nodes) in.fail("$Elements before $Nodes");
      if (major == 2) {
        reader.elements_v2();
      } else {
        reader.elements_v41();
      }
      in.expect("$EndElements");
    } else {
      in.skip_section(section);
    }
  }
  return mesh;
}

void write_gmsh41_binary_impl(const std::string& path, const TetMesh& mesh) {
  const auto [lo, hi] = bounding_box(mesh.nodes);
  const std::size_t n = mesh.nodes.size();
  const std::size_t m = mesh.tets.size();
  std::string out;
  out.reserve(256 + n * 32 + m * 40);
  out += "$MeshFormat\n4.1 1 8\n";
  append_int32(out, 1);
  out += "\n$EndMeshFormat\n$Entities\n";
  for (int count : {0, 0, 0, 1}) append_size(out, static_cast<std::uint64_t>(count));
  append_int32(out, 1);  // volume tag
  for (double c : lo) append_f64(out, c);
  for (double c : hi) append_f64(out, c);
  append_size(out, 0);  // physical tags
  append_size(out, 0);  // bounding surfaces
  out += "\n$EndEntities\n$Nodes\n";
  append_one_block_header(out, n, 0);  // not parametric
  for (std::size_t i = 0; i < n; ++i) append_size(out, i + 1);
  for (const Vec3& p : mesh.nodes)
    for (double c : p) append_f64(out, c);
  out += "\n$EndNodes\n$Elements\n";
  append_one_block_header(out, m, kGmshTet4);
  for (std::size_t i = 0; i < m; ++i) {
    append_size(out, i + 1);
    for (std::uint32_t v : mesh.tets[i]) append_size(out, std::uint64_t{v} + 1);
  }
  out += "\n$EndElements\n";
  write_text_file(path, out);
}

}  // namespace tetseg::preprocess::detail
