#include "ply_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "tool_support.hpp"

namespace tetseg::tools {
namespace {

enum class Type { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

bool parse_type(const std::string& name, Type& type) {
  static const std::pair<const char*, Type> kNames[] = {
      {"char", Type::kI8},    {"int8", Type::kI8},     {"uchar", Type::kU8},
      {"uint8", Type::kU8},   {"short", Type::kI16},   {"int16", Type::kI16},
      {"ushort", Type::kU16}, {"uint16", Type::kU16},  {"int", Type::kI32},
      {"int32", Type::kI32},  {"uint", Type::kU32},    {"uint32", Type::kU32},
      {"float", Type::kF32},  {"float32", Type::kF32}, {"double", Type::kF64},
      {"float64", Type::kF64}};
  for (const auto& [n, t] : kNames)
    if (name == n) {
      type = t;
      return true;
    }
  return false;
}

std::size_t type_size(Type t) {
  switch (t) {
    case Type::kI8:
    case Type::kU8:
      return 1;
    case Type::kI16:
    case Type::kU16:
      return 2;
    case Type::kI32:
    case Type::kU32:
    case Type::kF32:
      return 4;
    case Type::kF64:
      return 8;
  }
  return 1;
}

bool is_float(Type t) {
  return t == Type::kF32 || t == Type::kF64;
}

struct Property {
  std::string name;
  Type type = Type::kF32;
  bool list = false;
  Type count_type = Type::kU8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

class Input {
 public:
  Input(std::string path, std::string bytes, std::size_t pos, int format)
      : m_path(std::move(path)), m_bytes(std::move(bytes)), m_pos(pos), m_format(format) {}

  std::size_t remaining() const { return m_bytes.size() - m_pos; }

  double read(Type t) {
    if (m_format == 0) return read_ascii();
    const std::size_t n = type_size(t);
    if (remaining() < n) fail("file ends inside the data");
    unsigned char b[8];
    std::memcpy(b, m_bytes.data() + m_pos, n);
    m_pos += n;
    if (m_format == 2) std::reverse(b, b + n);  // big endian -> little (host assumed little)
    switch (t) {
      case Type::kI8:
        return static_cast<std::int8_t>(b[0]);
      case Type::kU8:
        return b[0];
      case Type::kI16: {
        std::int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case Type::kU16: {
        std::uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case Type::kI32: {
        std::int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kU32: {
        std::uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kF32: {
        float v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case Type::kF64: {
        double v;
        std::memcpy(&v, b, 8);
        return v;
      }
    }
    return 0;
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw ToolError(kExitBadInput, m_path, "PLY: " + message);
  }

 private:
  double read_ascii() {
    while (m_pos < m_bytes.size() && std::isspace(static_cast<unsigned char>(m_bytes[m_pos])))
      ++m_pos;
    const std::size_t start = m_pos;
    while (m_pos < m_bytes.size() && !std::isspace(static_cast<unsigned char>(m_bytes[m_pos])))
      ++m_pos;
    if (start == m_pos) fail("file ends inside the data");
    const std::string token = m_bytes.substr(start, m_pos - start);
    char* end = nullptr;
    const double v = std::strtod(token.c_str(), &end);
    if (end != token.c_str() + token.size()) fail("not a number: '" + token + "'");
    return v;
  }

  std::string m_path;
  std::string m_bytes;
  std::size_t m_pos;
  int m_format;  // 0 ascii, 1 binary little endian, 2 binary big endian
};

}  // namespace

RenderMesh read_colored_ply(const std::string& path, const std::string& scalar_property) {
  static const char* const kColorNames[3] = {"red", "green", "blue"};
  std::ifstream file(path, std::ios::binary);
  if (!file) throw ToolError(kExitBadInput, path, "cannot open the file");
  std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
  auto fail = [&](const std::string& message) {
    throw ToolError(kExitBadInput, path, "PLY: " + message);
  };
  const std::size_t header_end = bytes.find("end_header");
  if (bytes.compare(0, 3, "ply") != 0 || header_end == std::string::npos)
    fail("not a PLY file (missing 'ply' or 'end_header')");
  std::size_t data_start = bytes.find('\n', header_end);
  if (data_start == std::string::npos) fail("no data after the header");
  ++data_start;

  std::istringstream header(bytes.substr(0, header_end));
  std::string line;
  int format = -1;
  std::vector<Element> elements;
  while (std::getline(header, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") {
      std::string name;
      words >> name;
      format = name == "ascii"                  ? 0
               : name == "binary_little_endian" ? 1
               : name == "binary_big_endian"    ? 2
                                                : -1;
      if (format < 0) fail("unknown format '" + name + "'");
    } else if (word == "element") {
      Element e;
      long long count = -1;
      words >> e.name >> count;
      // Every element takes at least one byte (binary) or one character (ASCII).
      if (!words || count < 0 || static_cast<std::uint64_t>(count) > bytes.size())
        fail("bad element line '" + line + "'");
      e.count = static_cast<std::uint64_t>(count);
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) fail("property before any element");
      Property p;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> p.name;
        p.list = true;
        if (!parse_type(count_type, p.count_type) || !parse_type(item_type, p.type))
          fail("bad list property '" + line + "'");
      } else {
        words >> p.name;
        if (!parse_type(type, p.type)) fail("bad property type '" + type + "'");
      }
      elements.back().properties.push_back(p);
    }
  }
  if (format < 0) fail("missing format line");

  Input in(path, std::move(bytes), data_start, format);
  RenderMesh mesh;
  std::vector<double> values;  // per triangle, when colouring by a scalar
  for (const Element& e : elements) {
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    int xyz[3] = {-1, -1, -1}, rgb[3] = {-1, -1, -1}, list = -1, scalar = -1;
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const std::string& n = e.properties[i].name;
      for (int k = 0; k < 3; ++k) {
        if (n == std::string(1, "xyz"[k])) xyz[k] = static_cast<int>(i);
        if (n == kColorNames[k]) rgb[k] = static_cast<int>(i);
      }
      if (!e.properties[i].list && !scalar_property.empty() && n == scalar_property)
        scalar = static_cast<int>(i);
      if (e.properties[i].list && (n == "vertex_indices" || n == "vertex_index"))
        list = static_cast<int>(i);
    }
    if (is_vertex && (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0)) fail("vertices without x, y, z");
    if (is_face && list < 0) fail("faces without vertex_indices");
    if (is_face && !scalar_property.empty() && scalar < 0)
      fail("faces have no property '" + scalar_property + "'");
    if (e.count > in.remaining()) fail("element '" + e.name + "' count exceeds the file size");
    if (is_vertex) mesh.positions.reserve(e.count);
    for (std::uint64_t r = 0; r < e.count; ++r) {
      std::array<double, 3> pos{0, 0, 0};
      Rgb color{180, 180, 180};
      std::vector<std::uint32_t> poly;
      double value = 0.0;
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (p.list) {
          const double count = in.read(p.count_type);
          if (!(count >= 0) || count > static_cast<double>(in.remaining())) fail("bad list length");
          for (std::uint64_t k = 0; k < static_cast<std::uint64_t>(count); ++k) {
            const double v = in.read(p.type);
            if (static_cast<int>(i) == list) {
              if (!(v >= 0) || v >= 4294967295.0) fail("bad vertex index");
              poly.push_back(static_cast<std::uint32_t>(v));
            }
          }
          continue;
        }
        const double v = in.read(p.type);
        if (is_face && static_cast<int>(i) == scalar) value = v;
        for (int k = 0; k < 3; ++k) {
          if (is_vertex && static_cast<int>(i) == xyz[k]) pos[k] = v;
          if (is_face && static_cast<int>(i) == rgb[k]) {
            const double c = is_float(p.type) ? v * 255.0 : v;
            color[k] = static_cast<std::uint8_t>(std::clamp(std::lround(c), 0L, 255L));
          }
        }
      }
      if (is_vertex) {
        if (!std::isfinite(pos[0]) || !std::isfinite(pos[1]) || !std::isfinite(pos[2]))
          fail("vertex coordinate is not finite");
        mesh.positions.push_back(pos);
      }
      if (is_face && poly.size() >= 3)
        for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
          mesh.triangles.push_back({poly[0], poly[k], poly[k + 1]});
          mesh.face_colors.push_back(color);
          values.push_back(value);
        }
    }
  }
  for (const auto& t : mesh.triangles)
    for (std::uint32_t v : t)
      if (v >= mesh.positions.size()) fail("face refers to a missing vertex");
  if (mesh.triangles.empty()) fail("no faces");
  if (!scalar_property.empty()) {
    double lo = 1e300, hi = -1e300;
    for (double v : values)
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    for (std::size_t t = 0; t < values.size(); ++t)
      mesh.face_colors[t] = scalar_color(hi > lo ? (values[t] - lo) / (hi - lo) : 0.5);
  }
  return mesh;
}

}  // namespace tetseg::tools
