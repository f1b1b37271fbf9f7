#include "mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

namespace tetseg::io {
namespace {

// ---------------------------------------------------------------- reading PLY

enum class Type { kI8, kU8, kI16, kU16, kI32, kU32, kF32, kF64 };

bool parse_type(const std::string& name, Type& type) {
  static const std::pair<const char*, Type> kNames[] = {
      {"char", Type::kI8},    {"int8", Type::kI8},     {"uchar", Type::kU8},
      {"uint8", Type::kU8},   {"short", Type::kI16},   {"int16", Type::kI16},
      {"ushort", Type::kU16}, {"uint16", Type::kU16},  {"int", Type::kI32},
      {"int32", Type::kI32},  {"uint", Type::kU32},    {"uint32", Type::kU32},
      {"float", Type::kF32},  {"float32", Type::kF32}, {"double", Type::kF64},
      {"float64", Type::kF64}};
  for (const auto& [n, t] : kNames) {
    if (name == n) {
      type = t;
      return true;
    }
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

// Thrown inside this file only; read_ply turns it into an IoStatus.
struct PlyError {
  std::string message;
};

[[noreturn]] void fail(const std::string& message) {
  throw PlyError{message};
}

enum class Encoding { kAscii, kLittle, kBig };

class Input {
 public:
  Input(const std::string& bytes, std::size_t pos, Encoding encoding)
      : m_bytes(bytes), m_pos(pos), m_encoding(encoding) {}

  std::size_t remaining() const { return m_bytes.size() - m_pos; }

  double read(Type t) {
    if (m_encoding == Encoding::kAscii) return read_ascii();
    const std::size_t n = type_size(t);
    if (remaining() < n) fail("file ends inside the data");
    unsigned char b[8];
    std::memcpy(b, m_bytes.data() + m_pos, n);
    m_pos += n;
    if (m_encoding == Encoding::kBig) std::reverse(b, b + n);  // to little (host assumed little)
    switch (t) {
      case Type::kI8:
        return static_cast<std::int8_t>(b[0]);
      case Type::kU8:
        return b[0];
      case Type::kI16:
        return decode<std::int16_t>(b);
      case Type::kU16:
        return decode<std::uint16_t>(b);
      case Type::kI32:
        return decode<std::int32_t>(b);
      case Type::kU32:
        return decode<std::uint32_t>(b);
      case Type::kF32:
        return decode<float>(b);
      case Type::kF64:
        return decode<double>(b);
    }
    return 0;
  }

 private:
  template <typename T>
  static double decode(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return static_cast<double>(v);
  }

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

  const std::string& m_bytes;
  std::size_t m_pos;
  Encoding m_encoding;
};

bool read_whole_file(const std::string& path, std::string& bytes) {
  std::ifstream file(path, std::ios::binary);
  if (!file) return false;
  bytes.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
  return !file.bad();
}

void parse_ply(const std::string& bytes, PlyMesh& mesh) {
  const std::size_t header_end = bytes.find("end_header");
  if (bytes.compare(0, 3, "ply") != 0 || header_end == std::string::npos)
    fail("not a PLY file (missing 'ply' or 'end_header')");
  std::size_t data_start = bytes.find('\n', header_end);
  if (data_start == std::string::npos) fail("no data after the header");
  ++data_start;

  std::istringstream header(bytes.substr(0, header_end));
  std::string line;
  bool have_format = false;
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  while (std::getline(header, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") {
      std::string name;
      words >> name;
      if (name == "ascii") {
        encoding = Encoding::kAscii;
      } else if (name == "binary_little_endian") {
        encoding = Encoding::kLittle;
      } else if (name == "binary_big_endian") {
        encoding = Encoding::kBig;
      } else {
        fail("unknown format '" + name + "'");
      }
      have_format = true;
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
  if (!have_format) fail("missing format line");

  Input in(bytes, data_start, encoding);
  for (const Element& e : elements) {
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    int xyz[3] = {-1, -1, -1}, list = -1;
    std::vector<int> face_property(e.properties.size(), -1);  // index into face_properties
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& p = e.properties[i];
      for (int k = 0; k < 3; ++k) {
        if (p.name == std::string(1, "xyz"[k])) xyz[k] = static_cast<int>(i);
      }
      if (is_face && p.list && (p.name == "vertex_indices" || p.name == "vertex_index"))
        list = static_cast<int>(i);
      if (is_face && !p.list) {
        face_property[i] = static_cast<int>(mesh.face_properties.size());
        mesh.face_properties.push_back({p.name, is_float(p.type), {}});
      }
    }
    if (is_vertex && e.count > 0 && (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0))
      fail("vertices without x, y, z");
    if (is_face && e.count > 0 && list < 0) fail("faces without vertex_indices");
    if (e.count > in.remaining()) fail("element '" + e.name + "' count exceeds the file size");
    if (is_vertex) mesh.vertices.reserve(e.count);
    for (std::uint64_t r = 0; r < e.count; ++r) {
      Point pos{0, 0, 0};
      std::vector<std::uint32_t> poly;
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
        for (int k = 0; k < 3; ++k) {
          if (is_vertex && static_cast<int>(i) == xyz[k]) pos[static_cast<std::size_t>(k)] = v;
        }
        if (face_property[i] >= 0) {
          mesh.face_properties[static_cast<std::size_t>(face_property[i])].values.push_back(v);
        }
      }
      if (is_vertex) {
        if (!std::isfinite(pos[0]) || !std::isfinite(pos[1]) || !std::isfinite(pos[2]))
          fail("vertex coordinate is not finite");
        mesh.vertices.push_back(pos);
      }
      if (is_face) mesh.faces.push_back(std::move(poly));
    }
  }
  for (const auto& face : mesh.faces) {
    for (std::uint32_t v : face) {
      if (v >= mesh.vertices.size()) fail("face refers to a missing vertex");
    }
  }
}

// ---------------------------------------------------------------- vertex positions

IoStatus read_obj_positions(std::istream& in, std::vector<double>& xyz) {
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
    std::istringstream ls(line.substr(2));
    double x, y, z;
    if (!(ls >> x >> y >> z)) return {"malformed vertex line: " + line};
    xyz.insert(xyz.end(), {x, y, z});
  }
  return {};
}

IoStatus read_medit_positions(std::istream& in, std::vector<double>& xyz) {
  std::string token;
  while (in >> token) {
    if (token != "Vertices") continue;
    long long count = -1;
    if (!(in >> count) || count < 0 || count > (1LL << 26)) return {"bad Vertices count"};
    xyz.reserve(static_cast<std::size_t>(count) * 3);
    for (long long i = 0; i < count; ++i) {
      double x, y, z;
      long long ref;
      if (!(in >> x >> y >> z >> ref)) return {"truncated Vertices section"};
      xyz.insert(xyz.end(), {x, y, z});
    }
    return {};
  }
  return {"no Vertices section"};
}

std::string lower_extension(const std::string& path) {
  const auto dot = path.find_last_of('.');
  const auto slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  std::string ext = path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// ---------------------------------------------------------------- writing

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

bool is_integer_type(const std::string& type) {
  return type != "Float64" && type != "Float32" && type != "double" && type != "float" &&
         type != "float32" && type != "float64";
}

std::string value_text(double v, bool integer) {
  if (integer) return std::to_string(static_cast<long long>(v));
  return number(v);
}

void write_data_array(std::ostringstream& out, const DataArray& array) {
  out << "<DataArray type=\"" << array.type << "\" Name=\"" << array.name
      << "\" format=\"ascii\">\n";
  const bool integer = is_integer_type(array.type);
  for (double v : array.values) out << value_text(v, integer) << '\n';
  out << "</DataArray>\n";
}

}  // namespace

const PlyProperty* PlyMesh::face_property(const std::string& name) const {
  for (const PlyProperty& p : face_properties) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

IoStatus read_ply(const std::string& path, PlyMesh& mesh) {
  mesh = PlyMesh{};
  std::string bytes;
  if (!read_whole_file(path, bytes)) return {"cannot open the file"};
  try {
    parse_ply(bytes, mesh);
  } catch (const PlyError& e) {
    mesh = PlyMesh{};
    return {"PLY: " + e.message};
  } catch (const std::bad_alloc&) {
    mesh = PlyMesh{};
    return {"PLY: out of memory"};
  }
  return {};
}

IoStatus read_vertex_positions(const std::string& path, std::vector<double>& xyz) {
  xyz.clear();
  const std::string ext = lower_extension(path);
  IoStatus status;
  if (ext == ".ply") {
    PlyMesh mesh;
    status = read_ply(path, mesh);
    for (const Point& p : mesh.vertices) xyz.insert(xyz.end(), p.begin(), p.end());
  } else if (ext == ".obj" || ext == ".mesh") {
    std::ifstream in(path, std::ios::binary);
    if (!in) return {"cannot open"};
    status = ext == ".obj" ? read_obj_positions(in, xyz) : read_medit_positions(in, xyz);
  } else {
    return {"unsupported extension (use .obj, .ply or .mesh)"};
  }
  if (!status.ok()) return status;
  for (double d : xyz) {
    if (!std::isfinite(d)) return {"non-finite coordinate"};
  }
  if (xyz.empty()) return {"no vertices"};
  return {};
}

std::string vtu_text(const UnstructuredGrid& grid) {
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "<UnstructuredGrid>\n"
      << "<Piece NumberOfPoints=\"" << grid.points.size() << "\" NumberOfCells=\""
      << grid.cells.size()
      << "\">\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (const Point& p : grid.points) {
    out << number(p[0]) << ' ' << number(p[1]) << ' ' << number(p[2]) << '\n';
  }
  out << "</DataArray>\n</Points>\n";
  if (!grid.point_data.empty()) {
    out << "<PointData>\n";
    for (const DataArray& array : grid.point_data) write_data_array(out, array);
    out << "</PointData>\n";
  }
  out << "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const auto& cell : grid.cells) {
    for (std::size_t i = 0; i < cell.size(); ++i) out << (i ? " " : "") << cell[i];
    out << '\n';
  }
  out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
  std::uint64_t offset = 0;
  for (const auto& cell : grid.cells) out << (offset += cell.size()) << '\n';
  out << "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (std::uint8_t type : grid.cell_types) out << int(type) << '\n';
  out << "</DataArray>\n</Cells>\n";
  if (!grid.cell_data.empty()) {
    out << "<CellData Scalars=\"" << grid.cell_data.front().name << "\">\n";
    for (const DataArray& array : grid.cell_data) write_data_array(out, array);
    out << "</CellData>\n";
  }
  out << "</Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  return out.str();
}

std::string ply_text(const PlyOutMesh& mesh) {
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\n";
  if (!mesh.comment.empty()) out << "comment " << mesh.comment << '\n';
  out << "element vertex " << mesh.vertices.size()
      << "\nproperty double x\nproperty double y\nproperty double z\nelement face "
      << mesh.triangles.size() << "\nproperty list uchar int vertex_indices\n";
  for (const PlyOutProperty& p : mesh.face_properties)
    out << "property " << p.type << ' ' << p.name << '\n';
  if (!mesh.edges.empty() || !mesh.edge_properties.empty()) {
    out << "element edge " << mesh.edges.size() << "\nproperty int vertex1\nproperty int vertex2\n";
    for (const PlyOutProperty& p : mesh.edge_properties)
      out << "property " << p.type << ' ' << p.name << '\n';
  }
  out << "end_header\n";
  for (const Point& p : mesh.vertices) {
    out << number(p[0]) << ' ' << number(p[1]) << ' ' << number(p[2]) << '\n';
  }
  auto properties = [&](const std::vector<PlyOutProperty>& list, std::size_t row) {
    for (const PlyOutProperty& p : list)
      out << ' ' << value_text(p.values[row], is_integer_type(p.type));
  };
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    out << "3 " << tri[0] << ' ' << tri[1] << ' ' << tri[2];
    properties(mesh.face_properties, t);
    out << '\n';
  }
  for (std::size_t e = 0; e < mesh.edges.size(); ++e) {
    out << mesh.edges[e][0] << ' ' << mesh.edges[e][1];
    properties(mesh.edge_properties, e);
    out << '\n';
  }
  return out.str();
}

}  // namespace tetseg::io
