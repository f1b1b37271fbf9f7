#include "mesh_positions.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include "tool_support.hpp"

namespace tetseg::tools {
namespace {

[[noreturn]] void bad(const std::string& path, const std::string& why) {
  throw ToolError(kExitBadInput, path, why);
}

std::vector<double> read_obj(const std::string& path, std::istream& in) {
  std::vector<double> xyz;
  std::string line;
  while (std::getline(in, line)) {
    if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
    std::istringstream ls(line.substr(2));
    double x, y, z;
    if (!(ls >> x >> y >> z)) bad(path, "malformed vertex line: " + line);
    xyz.insert(xyz.end(), {x, y, z});
  }
  return xyz;
}

std::vector<double> read_medit(const std::string& path, std::istream& in) {
  std::string token;
  while (in >> token) {
    if (token == "Vertices") {
      long long count = -1;
      if (!(in >> count) || count < 0 || count > (1LL << 26)) bad(path, "bad Vertices count");
      std::vector<double> xyz;
      xyz.reserve(std::size_t(count) * 3);
      for (long long i = 0; i < count; ++i) {
        double x, y, z;
        long long ref;
        if (!(in >> x >> y >> z >> ref)) bad(path, "truncated Vertices section");
        xyz.insert(xyz.end(), {x, y, z});
      }
      return xyz;
    }
  }
  bad(path, "no Vertices section");
}

std::size_t type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32")
    return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double decode(const unsigned char* p, const std::string& t, bool big_endian) {
  unsigned char b[8];
  const std::size_t n = type_size(t);
  for (std::size_t k = 0; k < n; ++k) b[k] = big_endian ? p[n - 1 - k] : p[k];
  if (t == "float" || t == "float32") {
    float f;
    std::memcpy(&f, b, 4);
    return f;
  }
  if (t == "double" || t == "float64") {
    double d;
    std::memcpy(&d, b, 8);
    return d;
  }
  std::uint64_t u = 0;
  for (std::size_t k = 0; k < n; ++k) u |= std::uint64_t(b[k]) << (8 * k);
  if (t[0] != 'u' && n < 8 && (u >> (8 * n - 1)) & 1)
    return double(std::int64_t(u) - (std::int64_t(1) << (8 * n)));
  return double(u);
}

std::vector<double> read_ply(const std::string& path, std::istream& in) {
  std::string line, format;
  std::getline(in, line);
  if (line.rfind("ply", 0) != 0) bad(path, "not a PLY file");
  long long vertex_count = -1;
  bool in_vertex = false, first_element = true;
  std::vector<std::pair<std::string, std::string>> props;  // type, name
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "format") {
      ls >> format;
    } else if (key == "element") {
      std::string name;
      long long count;
      ls >> name >> count;
      if (name == "vertex") {
        if (!first_element) bad(path, "the vertex element must come first");
        vertex_count = count;
        in_vertex = true;
      } else {
        in_vertex = false;
      }
      first_element = false;
    } else if (key == "property" && in_vertex) {
      std::string type, name;
      ls >> type >> name;
      if (type == "list") bad(path, "list properties in the vertex element are not supported");
      if (type_size(type) == 0) bad(path, "unknown property type " + type);
      props.push_back({type, name});
    } else if (key == "end_header") {
      break;
    }
  }
  if (vertex_count < 0 || vertex_count > (1LL << 26)) bad(path, "missing or bad vertex element");
  int ix = -1, iy = -1, iz = -1;
  for (std::size_t i = 0; i < props.size(); ++i) {
    if (props[i].second == "x") ix = int(i);
    if (props[i].second == "y") iy = int(i);
    if (props[i].second == "z") iz = int(i);
  }
  if (ix < 0 || iy < 0 || iz < 0) bad(path, "vertex element lacks x, y or z");
  std::vector<double> xyz;
  xyz.reserve(std::size_t(vertex_count) * 3);
  if (format == "ascii") {
    for (long long v = 0; v < vertex_count; ++v) {
      double val[3] = {0, 0, 0};
      for (std::size_t i = 0; i < props.size(); ++i) {
        double d;
        if (!(in >> d)) bad(path, "truncated vertex data");
        if (int(i) == ix) val[0] = d;
        if (int(i) == iy) val[1] = d;
        if (int(i) == iz) val[2] = d;
      }
      xyz.insert(xyz.end(), val, val + 3);
    }
    return xyz;
  }
  const bool big = format == "binary_big_endian";
  if (!big && format != "binary_little_endian") bad(path, "unknown PLY format " + format);
  std::size_t stride = 0;
  std::vector<std::size_t> offset;
  for (const auto& p : props) {
    offset.push_back(stride);
    stride += type_size(p.first);
  }
  std::vector<unsigned char> rec(stride);
  for (long long v = 0; v < vertex_count; ++v) {
    if (!in.read(reinterpret_cast<char*>(rec.data()), std::streamsize(stride)))
      bad(path, "truncated vertex data");
    xyz.push_back(decode(rec.data() + offset[ix], props[ix].first, big));
    xyz.push_back(decode(rec.data() + offset[iy], props[iy].first, big));
    xyz.push_back(decode(rec.data() + offset[iz], props[iz].first, big));
  }
  return xyz;
}

}  // namespace

std::vector<double> read_mesh_positions(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) bad(path, "cannot open");
  const std::string ext = extension_of(path);
  std::vector<double> xyz;
  if (ext == ".obj") {
    xyz = read_obj(path, in);
  } else if (ext == ".ply") {
    xyz = read_ply(path, in);
  } else if (ext == ".mesh") {
    xyz = read_medit(path, in);
  } else {
    bad(path, "unsupported extension (use .obj, .ply or .mesh)");
  }
  for (double d : xyz)
    if (!std::isfinite(d)) bad(path, "non-finite coordinate");
  if (xyz.empty()) bad(path, "no vertices");
  return xyz;
}

}  // namespace tetseg::tools
