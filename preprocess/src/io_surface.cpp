// Triangle surfaces: OFF, PLY, OBJ and STL through CGAL's polygon-soup readers (polygons are
// triangulated here), every other format through assimp (io_assimp.cpp). CGAL I/O only; no
// Mesh_3 in this translation unit.

#include <CGAL/IO/polygon_soup_io.h>
#include <CGAL/Polygon_mesh_processing/triangulate_hole.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <fstream>
#include <iterator>
#include <map>
#include <new>
#include <sstream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "cgal_mesh.hpp"
#include "io_text.hpp"
#include "tetseg/preprocess/io.hpp"

namespace tetseg::preprocess {
namespace detail {
TriangleMesh read_triangle_mesh_assimp(const std::string& path, bool keep_vertices,
                                       std::vector<std::uint32_t>* source_vertex_nodes);
}  // namespace detail

namespace {

using detail::cgal::Point;
using Polygon = std::vector<std::size_t>;
using detail::host_is_little_endian;
using detail::parse_int;
using detail::Tokenizer;

/// Polygons with more corners than this are refused (a hostile degree would make the
/// triangulation cubic in it).
constexpr std::size_t kMaxPolygonCorners = 4096;

/// Header counts of an ASCII OFF file checked against the bytes that follow, before CGAL's
/// reader resizes its arrays to them: a vertex needs at least 6 bytes ("0 0 0\n"), a face 8
/// ("3 0 1 2\n"), and every face line's corner count must fit on its line.
void check_off_counts(const std::string& path, const std::string& text) {
  Tokenizer tok(path, text, '#');
  const std::string_view keyword = tok.next("the OFF keyword");
  if (keyword.size() < 3 || keyword.substr(keyword.size() - 3) != "OFF")
    tok.fail("not an OFF file (first word '" + std::string(keyword.substr(0, 20)) + "')");
  if (keyword.find('n') != std::string_view::npos && tok.next_int("the dimension") != 3)
    tok.fail("only 3D OFF files are supported");
  std::string_view first = tok.next("the vertex count");
  if (first == "BINARY") tok.fail("binary OFF is not supported (save the surface as ASCII OFF)");
  std::int64_t counts[3] = {0, 0, 0};
  if (!parse_int(first, counts[0]))
    tok.fail("expected the vertex count, got '" + std::string(first.substr(0, 40)) + "'");
  counts[1] = tok.next_int("the face count");
  counts[2] = tok.next_int("the edge count");
  if (counts[0] < 0 || counts[1] < 0 || counts[2] < 0) tok.fail("negative count in the OFF header");
  const std::uint64_t bytes = text.size();
  const auto nv = static_cast<std::uint64_t>(counts[0]);
  const auto nf = static_cast<std::uint64_t>(counts[1]);
  if (nv > bytes / 6 || nf > bytes / 8 || nv * 6 + nf * 8 > bytes)
    tok.fail("header counts " + std::to_string(nv) + " vertices, " + std::to_string(nf) +
             " faces exceed what the file's " + std::to_string(bytes) + " bytes can hold");
  // Each face line starts with its corner count; the rest of the line must hold that many.
  tok.rest_of_line();
  std::vector<std::string_view> record;
  std::size_t line = 0;
  for (std::uint64_t i = 0; i < nv; ++i)
    if (!tok.next_record(record, line)) tok.fail_at(line, "unexpected end of file (vertices)");
  for (std::uint64_t i = 0; i < nf; ++i) {
    if (!tok.next_record(record, line)) tok.fail_at(line, "unexpected end of file (faces)");
    std::int64_t corners = 0;
    if (!parse_int(record[0], corners) || corners < 3 ||
        static_cast<std::uint64_t>(corners) + 1 > record.size() ||
        static_cast<std::uint64_t>(corners) > kMaxPolygonCorners)
      tok.fail_at(line, "malformed face (corner count '" + std::string(record[0].substr(0, 20)) +
                            "' with " + std::to_string(record.size() - 1) + " values after it)");
  }
}

/// One PLY property: a scalar, or a list with a count of `count_bytes` (signed or not) and
/// items of `bytes` each.
struct PlyProperty {
  bool list = false;
  std::uint64_t count_bytes = 0;
  bool count_signed = false;
  std::uint64_t bytes = 0;
};

struct PlyElement {
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

/// Size in bytes and signedness of a PLY scalar type; {0, false} when unknown.
std::pair<std::uint64_t, bool> ply_type(const std::string& type) {
  static const std::map<std::string, std::pair<std::uint64_t, bool>> kTypes = {
      {"char", {1, true}},  {"int8", {1, true}},    {"uchar", {1, false}},  {"uint8", {1, false}},
      {"short", {2, true}}, {"int16", {2, true}},   {"ushort", {2, false}}, {"uint16", {2, false}},
      {"int", {4, true}},   {"int32", {4, true}},   {"uint", {4, false}},   {"uint32", {4, false}},
      {"float", {4, true}}, {"float32", {4, true}}, {"double", {8, true}},  {"float64", {8, true}}};
  const auto it = kTypes.find(type);
  return it == kTypes.end() ? std::pair<std::uint64_t, bool>{0, false} : it->second;
}

/// Walks a PLY file's header and body before CGAL's reader sees it, so that no count can make
/// that reader allocate or loop beyond the file: element counts are checked against the bytes
/// left, and every list's length against the bytes (binary) or tokens (ASCII) that follow.
/// Also refuses what CGAL's reader would crash on (a property before any element).
void check_ply_layout(const std::string& path, const std::string& text) {
  const std::size_t end = text.find("end_header");
  if (text.compare(0, 3, "ply") != 0 || end == std::string::npos)
    throw InputError(path, "not a PLY file (no 'ply' ... 'end_header' header)");
  const std::size_t body = text.find('\n', end);
  if (body == std::string::npos) throw InputError(path, "PLY header has no line end");
  std::istringstream header(text.substr(0, end));
  std::string format;
  std::vector<PlyElement> elements;
  std::string line;
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") {
      words >> format;
    } else if (word == "element") {
      std::string name;
      std::string number;
      words >> name >> number;
      std::int64_t n = -1;
      if (!parse_int(number, n) || n < 0)
        throw InputError(path, "PLY element '" + name.substr(0, 40) + "' has an invalid count '" +
                                   number.substr(0, 40) + "'");
      elements.push_back({static_cast<std::uint64_t>(n), {}});
    } else if (word == "property") {
      // CGAL's reader adds a property to its last element without checking there is one.
      if (elements.empty()) throw InputError(path, "PLY property before any element");
      std::string type;
      words >> type;
      PlyProperty property;
      if (type == "list") {
        std::string count_type;
        std::string item_type;
        words >> count_type >> item_type;
        const auto [count_bytes, count_signed] = ply_type(count_type);
        if (count_bytes == 0 || count_bytes > 4 || count_type.find("float") == 0)
          throw InputError(path, "PLY list with count type '" + count_type.substr(0, 20) + "'");
        property = {true, count_bytes, count_signed, ply_type(item_type).first};
      } else {
        property.bytes = ply_type(type).first;
      }
      if (property.bytes == 0) throw InputError(path, "PLY property of unknown type");
      elements.back().properties.push_back(property);
    }
  }
  const bool ascii = format == "ascii";
  if (!ascii && format != "binary_little_endian" && format != "binary_big_endian")
    throw InputError(path, "PLY format '" + format.substr(0, 40) + "' is not supported");
  const bool swap = (format == "binary_big_endian") == host_is_little_endian();
  std::uint64_t pos = body + 1;
  auto fail = [&](const std::string& what) {
    throw InputError(path, "PLY body ends early or holds a bad list length (" + what + ")");
  };
  Tokenizer tok(path, std::string_view(text).substr(pos), '\0');
  for (const PlyElement& element : elements) {
    std::uint64_t min_bytes = 0;
    for (const PlyProperty& p : element.properties)
      min_bytes += ascii ? 2 : p.count_bytes + p.bytes;
    if (element.count > 0 &&
        (min_bytes == 0 || element.count > (text.size() - pos + 1) / min_bytes))
      fail("element count " + std::to_string(element.count));
    for (std::uint64_t i = 0; i < element.count; ++i)
      for (const PlyProperty& p : element.properties) {
        std::int64_t length = 1;
        if (ascii) {
          if (p.list) length = tok.next_int("a PLY list length");
          if (length < 0 || static_cast<std::uint64_t>(length) > text.size() / 2)
            fail("list length " + std::to_string(length));
          for (std::int64_t k = 0; k < length; ++k) tok.next("a PLY value");
          continue;
        }
        if (p.list) {
          if (text.size() - pos < p.count_bytes) fail("list length cut off");
          unsigned char raw[4] = {0, 0, 0, 0};
          std::memcpy(raw, text.data() + pos, p.count_bytes);
          if (swap) std::reverse(raw, raw + p.count_bytes);
          std::uint32_t value = 0;
          for (std::uint64_t k = p.count_bytes; k-- > 0;) value = (value << 8) | raw[k];
          const std::uint64_t sign_bit = std::uint64_t{1} << (8 * p.count_bytes - 1);
          if (p.count_signed && (value & sign_bit) != 0) fail("negative list length");
          length = value;
          pos += p.count_bytes;
        }
        const auto needed = static_cast<std::uint64_t>(length) * p.bytes;
        if (needed > text.size() - pos) fail("value cut off");
        pos += needed;
      }
  }
}

/// Whether reading `polygons` over `points` left anything a caller could index out of range.
void check_soup(const std::string& path, const std::vector<Point>& points,
                const std::vector<Polygon>& polygons) {
  for (const Point& p : points)
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z()))
      throw InputError(path, "vertex coordinate is not finite");
  for (const Polygon& polygon : polygons) {
    if (polygon.size() > kMaxPolygonCorners)
      throw InputError(path, "polygon with " + std::to_string(polygon.size()) +
                                 " corners (at most " + std::to_string(kMaxPolygonCorners) + ")");
    for (std::size_t v : polygon)
      if (v >= points.size())
        throw InputError(path, "face refers to vertex " + std::to_string(v) + " out of range (" +
                                   std::to_string(points.size()) + " vertices)");
  }
}

/// Splits a polygon of n >= 4 corners into n - 2 triangles: CGAL's hole triangulation of the
/// closed polyline (minimum area, then dihedral angles; non-planar polygons are fine), or a
/// fan from the first corner when that finds nothing (collinear corners).
void triangulate_polygon(const std::vector<Point>& points, const Polygon& polygon,
                         std::vector<std::array<std::size_t, 3>>& out) {
  std::vector<Point> polyline;
  polyline.reserve(polygon.size());
  for (std::size_t v : polygon) polyline.push_back(points[v]);
  std::vector<CGAL::Triple<int, int, int>> patch;
  CGAL::Polygon_mesh_processing::triangulate_hole_polyline(polyline, std::back_inserter(patch));
  if (patch.size() + 2 == polygon.size()) {
    for (const auto& t : patch)
      out.push_back({polygon[static_cast<std::size_t>(t.first)],
                     polygon[static_cast<std::size_t>(t.second)],
                     polygon[static_cast<std::size_t>(t.third)]});
    return;
  }
  for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
    out.push_back({polygon[0], polygon[k], polygon[k + 1]});
}

/// A whole token as a number, as CGAL's stream reader would read it (a leading '+' allowed);
/// false for anything else, including values out of range (detail::parse_double turns those
/// into inf or 0 instead, where CGAL's reader fails).
bool plain_number(std::string_view token, double& value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return !token.empty() && ec == std::errc() && ptr == end;
}

}  // namespace

namespace detail {

bool read_plain_off(const std::string& text, std::vector<Vec3>& points,
                    std::vector<std::vector<std::size_t>>& polygons) {
  points.clear();
  polygons.clear();
  Tokenizer tok("", text, '#');
  std::vector<std::string_view> record;
  std::size_t line = 0;
  auto give_up = [&] {
    points.clear();
    polygons.clear();
    return false;
  };
  if (!tok.next_record(record, line) || record.size() != 1 || record[0] != "OFF") return false;
  std::int64_t counts[3];
  if (!tok.next_record(record, line) || record.size() != 3) return false;
  for (int k = 0; k < 3; ++k) {
    if (!parse_int(record[static_cast<std::size_t>(k)], counts[k]) || counts[k] < 0) {
      return false;
    }
  }
  if (counts[0] == 0 || counts[1] == 0) return false;
  const std::size_t vertex_count = static_cast<std::size_t>(counts[0]);
  const std::size_t face_count = static_cast<std::size_t>(counts[1]);
  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line 8 ("3 0 1 2\n"): hostile
  // counts reserve no more than the file could hold.
  points.reserve(std::min(vertex_count, text.size() / 6));
  polygons.reserve(std::min(face_count, text.size() / 8));
  for (std::size_t v = 0; v < vertex_count; ++v) {
    Vec3 p;
    if (!tok.next_record(record, line) || record.size() != 3) return give_up();
    for (std::size_t a = 0; a < 3; ++a) {
      if (!plain_number(record[a], p[a])) return give_up();
    }
    points.push_back(p);
  }
  for (std::size_t f = 0; f < face_count; ++f) {
    std::int64_t corners = 0;
    if (!tok.next_record(record, line) || !parse_int(record[0], corners)) return give_up();
    // Tokens after the corners (a face colour) are ignored, as CGAL's reader does.
    if (corners < 1 || static_cast<std::size_t>(corners) > kMaxPolygonCorners ||
        record.size() < static_cast<std::size_t>(corners) + 1) {
      return give_up();
    }
    std::vector<std::size_t> polygon(static_cast<std::size_t>(corners));
    for (std::size_t k = 0; k < polygon.size(); ++k) {
      std::int64_t index = 0;
      if (!parse_int(record[k + 1], index) || index < 0 ||
          static_cast<std::size_t>(index) >= vertex_count) {
        return give_up();
      }
      polygon[k] = static_cast<std::size_t>(index);
    }
    polygons.push_back(std::move(polygon));
  }
  if (!tok.at_end()) return give_up();
  return true;
}

}  // namespace detail

namespace {

/// Hash and equality of positions as std::map<Vec3> orders them: by value, -0 equal to +0.
struct PositionHash {
  std::size_t operator()(const Vec3& p) const {
    std::size_t h = 0;
    for (const double c : p) {
      const double v = c == 0.0 ? 0.0 : c;
      std::uint64_t bits;
      std::memcpy(&bits, &v, sizeof bits);
      h = (h ^ bits) * 0x100000001b3ull + (h >> 29);
    }
    return h;
  }
};
struct PositionEqual {
  bool operator()(const Vec3& a, const Vec3& b) const {
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
  }
};

TriangleMesh read_with_cgal(const std::string& path, const std::string& ext, bool keep_vertices,
                            std::vector<std::uint32_t>* source_vertex_nodes) {
  const std::string text = detail::read_file_text(path);
  if (text.empty()) throw InputError(path, "empty file");
  if (ext == ".ply") check_ply_layout(path, text);
  std::vector<Point> points;
  std::vector<Polygon> polygons;
  bool ok = false;
  const auto np = CGAL::parameters::verbose(false);
  std::vector<Vec3> plain_points;
  if (ext == ".off" && detail::read_plain_off(text, plain_points, polygons)) {
    // Plain ASCII OFF, parsed here (CGAL's stream reader took 5-10x longer); anything else
    // goes to CGAL's reader.
    points = detail::cgal::to_points(plain_points);
    ok = true;
  } else if (ext == ".off") {
    check_off_counts(path, text);
    ok = CGAL::IO::read_OFF(path, points, polygons, np);
  } else if (ext == ".ply") {
    ok = CGAL::IO::read_PLY(path, points, polygons, np);
  } else if (ext == ".obj") {
    ok = CGAL::IO::read_OBJ(path, points, polygons, np);
  } else {
    ok = CGAL::IO::read_STL(path, points, polygons, np);
  }
  if (!ok) throw InputError(path, "malformed " + ext.substr(1) + " file (CGAL's reader failed)");
  check_soup(path, points, polygons);
  std::vector<std::array<std::size_t, 3>> triangles;
  triangles.reserve(polygons.size());
  for (const Polygon& polygon : polygons) {
    if (polygon.size() < 3) continue;  // points and edges are dropped, as with assimp
    if (polygon.size() == 3) {
      triangles.push_back({polygon[0], polygon[1], polygon[2]});
    } else {
      triangulate_polygon(points, polygon, triangles);
    }
  }
  TriangleMesh mesh;
  const bool stl = ext == ".stl";
  if (keep_vertices && !stl) {  // the file's vertices, all of them, in their order
    mesh.vertices.reserve(points.size());
    for (const Point& p : points) mesh.vertices.push_back(detail::cgal::to_vec3(p));
    for (const auto& t : triangles)
      mesh.triangles.push_back({static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
                                static_cast<std::uint32_t>(t[2])});
    return mesh;
  }
  // Vertices are merged by exact position (STL repeats corners), numbered in order of first use.
  // STL: the file's vertices are the facets' corners, three per facet in file order;
  // source_vertex_nodes records each corner's vertex.
  const bool record_corners = keep_vertices && stl && source_vertex_nodes != nullptr;
  if (record_corners) source_vertex_nodes->clear();
  std::unordered_map<Vec3, std::uint32_t, PositionHash, PositionEqual> index_of;
  index_of.reserve(points.size());
  for (const auto& t : triangles) {
    Tri tri;
    for (std::size_t k = 0; k < 3; ++k) {
      const Point& p = points[t[k]];
      const auto [it, inserted] = index_of.emplace(
          detail::cgal::to_vec3(p), static_cast<std::uint32_t>(mesh.vertices.size()));
      if (inserted) mesh.vertices.push_back(it->first);
      tri[k] = it->second;
      if (record_corners) source_vertex_nodes->push_back(it->second);
    }
    mesh.triangles.push_back(tri);
  }
  return mesh;
}

}  // namespace

namespace {

TriangleMesh read_triangle_mesh(const std::string& path, bool keep_vertices,
                                std::vector<std::uint32_t>* source_vertex_nodes) {
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path, "cannot open file");
  }
  const std::string ext = detail::lower_extension(path);
  const bool cgal = ext == ".off" || ext == ".ply" || ext == ".obj" || ext == ".stl";
  TriangleMesh mesh;
  // The third-party readers may throw anything (allocation failures on hostile sizes, CGAL
  // precondition failures); every one becomes an InputError naming the file.
  try {
    if (source_vertex_nodes) source_vertex_nodes->clear();
    mesh = cgal ? read_with_cgal(path, ext, keep_vertices, source_vertex_nodes)
                : detail::read_triangle_mesh_assimp(path, keep_vertices, source_vertex_nodes);
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw InputError(path, "reading: out of memory (sizes in the file too large?)");
  } catch (const std::exception& e) {
    throw InputError(path, std::string("reading: ") + e.what());
  }
  if (mesh.triangles.empty()) throw InputError(path, "no triangles in file");
  return mesh;
}

}  // namespace

TriangleMesh read_triangle_mesh(const std::string& path) {
  return read_triangle_mesh(path, false, nullptr);
}

TriangleMesh read_triangle_mesh_keeping_vertices(const std::string& path,
                                                 std::vector<std::uint32_t>* source_vertex_nodes) {
  return read_triangle_mesh(path, true, source_vertex_nodes);
}

}  // namespace tetseg::preprocess
