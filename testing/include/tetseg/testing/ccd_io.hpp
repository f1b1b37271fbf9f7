#pragma once
/// \file
/// Readers for the CCD reference data (header-only; used by tetseg-ccd and by the runtime
/// tests): exact rational CSV queries, binary/ASCII PLY triangle soups, flat JSON arrays,
/// and the edge numbering of the scalable-CCD data. Every reader throws std::runtime_error
/// with a message (no file name: callers add it) on malformed input; none trusts a count.

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace tetseg::test::ccd_io {

using Vec3 = std::array<double, 3>;

/// Exact conversion of a decimal rational "num/den" (den a power of two, any number of digits)
/// to the nearest double (round half to even). Throws on a non-dyadic denominator, on a
/// malformed number and on values outside the normal double range.
inline double rational_to_double(const std::string& num_text, const std::string& den_text) {
  auto parse = [](const std::string& text, bool allow_sign, bool& negative) {
    std::vector<std::uint32_t> limbs;  // little-endian base 2^32
    std::size_t i = 0;
    negative = false;
    if (allow_sign && i < text.size() && (text[i] == '-' || text[i] == '+')) {
      negative = text[i] == '-';
      ++i;
    }
    if (i == text.size()) throw std::runtime_error("empty number '" + text + "'");
    for (; i < text.size(); ++i) {
      const char c = text[i];
      if (c < '0' || c > '9') throw std::runtime_error("bad digit in '" + text + "'");
      std::uint64_t carry = static_cast<std::uint64_t>(c - '0');
      for (auto& limb : limbs) {
        const std::uint64_t v = std::uint64_t{limb} * 10u + carry;
        limb = static_cast<std::uint32_t>(v);
        carry = v >> 32;
      }
      if (carry) limbs.push_back(static_cast<std::uint32_t>(carry));
    }
    while (!limbs.empty() && limbs.back() == 0) limbs.pop_back();
    return limbs;
  };
  auto bit_length = [](const std::vector<std::uint32_t>& limbs) -> long {
    if (limbs.empty()) return 0;
    long bits = static_cast<long>(limbs.size() - 1) * 32;
    std::uint32_t top = limbs.back();
    while (top) {
      ++bits;
      top >>= 1;
    }
    return bits;
  };
  auto bit = [](const std::vector<std::uint32_t>& limbs, long index) -> bool {
    if (index < 0) return false;
    const auto limb = static_cast<std::size_t>(index / 32);
    return limb < limbs.size() && ((limbs[limb] >> (index % 32)) & 1u);
  };
  bool negative = false;
  bool den_negative = false;
  const auto num = parse(num_text, true, negative);
  const auto den = parse(den_text, false, den_negative);
  const long den_bits = bit_length(den);
  if (den_bits == 0) throw std::runtime_error("zero denominator");
  for (long b = 0; b + 1 < den_bits; ++b)
    if (bit(den, b)) throw std::runtime_error("denominator " + den_text + " is not a power of two");
  const long exponent = -(den_bits - 1);
  const long num_bits = bit_length(num);
  if (num_bits == 0) return 0.0;
  // Top 53 bits, round bit, sticky bit.
  std::uint64_t mantissa = 0;
  for (long b = num_bits - 1; b >= std::max(0L, num_bits - 53); --b)
    mantissa = (mantissa << 1) | (bit(num, b) ? 1u : 0u);
  long shift = num_bits > 53 ? num_bits - 53 : 0;
  if (shift > 0) {
    const bool round = bit(num, shift - 1);
    bool sticky = false;
    for (long b = 0; b < shift - 1 && !sticky; ++b) sticky = bit(num, b);
    if (round && (sticky || (mantissa & 1u))) {
      ++mantissa;
      if (mantissa == (std::uint64_t{1} << 53)) {
        mantissa >>= 1;
        ++shift;
      }
    }
  }
  const long e = shift + exponent;
  if (e + 53 > 1000 || e < -1000) throw std::runtime_error("value out of double range");
  const double value = std::ldexp(static_cast<double>(mantissa), static_cast<int>(e));
  return negative ? -value : value;
}

/// One reference query: 8 points in the README row order and the ground truth.
struct Query {
  std::array<Vec3, 8> points{};
  bool truth = false;
};

/// Reads a rational CSV (8 rows per query; 7 columns with truth or 6 without).
inline std::vector<Query> read_query_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open");
  std::vector<Query> queries;
  std::string line;
  int row = 0;
  long line_number = 0;
  Query current;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) cells.push_back(cell);
    if (cells.size() != 6 && cells.size() != 7)
      throw std::runtime_error("line " + std::to_string(line_number) + ": expected 6 or 7 columns");
    try {
      for (int k = 0; k < 3; ++k)
        current.points[static_cast<std::size_t>(row)][static_cast<std::size_t>(k)] =
            rational_to_double(cells[2 * k], cells[2 * k + 1]);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("line " + std::to_string(line_number) + ": " + e.what());
    }
    if (cells.size() == 7) {
      if (cells[6] != "0" && cells[6] != "1")
        throw std::runtime_error("line " + std::to_string(line_number) + ": truth not 0/1");
      current.truth = cells[6] == "1";
    }
    if (++row == 8) {
      queries.push_back(current);
      current = Query{};
      row = 0;
    }
  }
  if (row != 0) throw std::runtime_error("truncated query (row count not a multiple of 8)");
  return queries;
}

/// A triangle soup.
struct Mesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> faces;
};

/// Reads a PLY file (ascii, binary_little_endian or binary_big_endian). Vertex x, y, z of any
/// scalar type, any extra properties (skipped); faces as a list property of triangles.
inline Mesh read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0)
    throw std::runtime_error("not a PLY file");
  enum class Format { kAscii, kLittle, kBig } format = Format::kAscii;
  struct Property {
    std::string name, type, count_type;
    bool list = false;
  };
  struct Element {
    std::string name;
    std::uint64_t count = 0;
    std::vector<Property> properties;
  };
  std::vector<Element> elements;
  bool header_done = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::stringstream ss(line);
    std::string word;
    ss >> word;
    if (word == "format") {
      std::string f;
      ss >> f;
      if (f == "ascii")
        format = Format::kAscii;
      else if (f == "binary_little_endian")
        format = Format::kLittle;
      else if (f == "binary_big_endian")
        format = Format::kBig;
      else
        throw std::runtime_error("unknown PLY format '" + f + "'");
    } else if (word == "element") {
      Element e;
      ss >> e.name >> e.count;
      if (!ss || e.count > (1u << 28)) throw std::runtime_error("bad element line '" + line + "'");
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) throw std::runtime_error("property before element");
      Property p;
      ss >> p.type;
      if (p.type == "list") {
        p.list = true;
        ss >> p.count_type >> p.type;
      }
      ss >> p.name;
      if (!ss) throw std::runtime_error("bad property line '" + line + "'");
      elements.back().properties.push_back(p);
    } else if (word == "end_header") {
      header_done = true;
      break;
    }
  }
  if (!header_done) throw std::runtime_error("PLY header without end_header");
  auto type_size = [](const std::string& t) -> std::size_t {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" ||
        t == "float32")
      return 4;
    if (t == "double" || t == "float64") return 8;
    throw std::runtime_error("unknown PLY type '" + t + "'");
  };
  const bool swap = format == Format::kBig;
  auto read_scalar = [&](const std::string& t) -> double {
    if (format == Format::kAscii) {
      double v;
      if (!(in >> v)) throw std::runtime_error("truncated ASCII PLY data");
      return v;
    }
    unsigned char bytes[8];
    const std::size_t n = type_size(t);
    if (!in.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(n)))
      throw std::runtime_error("truncated binary PLY data");
    if (swap) std::reverse(bytes, bytes + n);
    if (t == "char" || t == "int8") return static_cast<std::int8_t>(bytes[0]);
    if (t == "uchar" || t == "uint8") return bytes[0];
    if (n == 2) {
      std::uint16_t v;
      std::memcpy(&v, bytes, 2);
      return (t == "short" || t == "int16") ? static_cast<double>(static_cast<std::int16_t>(v)) : v;
    }
    if (t == "float" || t == "float32") {
      float v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    if (n == 4) {
      std::uint32_t v;
      std::memcpy(&v, bytes, 4);
      return (t == "int" || t == "int32") ? static_cast<double>(static_cast<std::int32_t>(v)) : v;
    }
    double v;
    std::memcpy(&v, bytes, 8);
    return v;
  };
  Mesh mesh;
  for (const auto& e : elements) {
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    for (std::uint64_t i = 0; i < e.count; ++i) {
      Vec3 v{0, 0, 0};
      int found = 0;
      for (const auto& p : e.properties) {
        if (p.list) {
          const double count = read_scalar(p.count_type);
          if (!(count >= 0 && count <= 1024)) throw std::runtime_error("bad list length");
          std::vector<double> items(static_cast<std::size_t>(count));
          for (auto& item : items) item = read_scalar(p.type);
          if (is_face && (p.name == "vertex_indices" || p.name == "vertex_index")) {
            if (items.size() != 3) throw std::runtime_error("face is not a triangle");
            std::array<std::uint32_t, 3> f{};
            for (int k = 0; k < 3; ++k) {
              const double idx = items[static_cast<std::size_t>(k)];
              if (!(idx >= 0 && idx < 4294967295.0)) throw std::runtime_error("bad face index");
              f[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(idx);
            }
            mesh.faces.push_back(f);
          }
        } else {
          const double value = read_scalar(p.type);
          if (is_vertex) {
            if (p.name == "x") v[0] = value, found |= 1;
            if (p.name == "y") v[1] = value, found |= 2;
            if (p.name == "z") v[2] = value, found |= 4;
          }
        }
      }
      if (is_vertex) {
        if (found != 7) throw std::runtime_error("vertex without x, y, z");
        mesh.vertices.push_back(v);
      }
    }
  }
  for (const auto& f : mesh.faces)
    for (auto idx : f)
      if (idx >= mesh.vertices.size()) throw std::runtime_error("face index out of range");
  return mesh;
}

/// Reads a whole text file.
inline std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Parses a JSON array of [int, int] pairs.
inline std::vector<std::array<std::int64_t, 2>> parse_json_pairs(const std::string& text) {
  std::vector<std::array<std::int64_t, 2>> out;
  std::size_t i = 0;
  auto skip = [&] {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  };
  auto expect = [&](char c) {
    skip();
    if (i >= text.size() || text[i] != c)
      throw std::runtime_error(std::string("JSON: expected '") + c + "' at offset " +
                               std::to_string(i));
    ++i;
  };
  auto number = [&]() -> std::int64_t {
    skip();
    std::size_t start = i;
    if (i < text.size() && text[i] == '-') ++i;
    while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
    if (start == i || i - start > 18)
      throw std::runtime_error("JSON: bad integer at offset " + std::to_string(start));
    return std::stoll(text.substr(start, i - start));
  };
  expect('[');
  skip();
  if (i < text.size() && text[i] == ']') return out;
  for (;;) {
    expect('[');
    const auto a = number();
    expect(',');
    const auto b = number();
    expect(']');
    out.push_back({a, b});
    skip();
    if (i < text.size() && text[i] == ',') {
      ++i;
      continue;
    }
    expect(']');
    break;
  }
  return out;
}

/// Parses a JSON array of booleans.
inline std::vector<bool> parse_json_bools(const std::string& text) {
  std::vector<bool> out;
  std::size_t i = 0;
  auto skip = [&] {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  };
  skip();
  if (i >= text.size() || text[i] != '[') throw std::runtime_error("JSON: expected '['");
  ++i;
  skip();
  if (i < text.size() && text[i] == ']') return out;
  for (;;) {
    skip();
    if (text.compare(i, 4, "true") == 0) {
      out.push_back(true);
      i += 4;
    } else if (text.compare(i, 5, "false") == 0) {
      out.push_back(false);
      i += 5;
    } else {
      throw std::runtime_error("JSON: expected a boolean at offset " + std::to_string(i));
    }
    skip();
    if (i < text.size() && text[i] == ',') {
      ++i;
      continue;
    }
    if (i < text.size() && text[i] == ']') break;
    throw std::runtime_error("JSON: expected ',' or ']' at offset " + std::to_string(i));
  }
  return out;
}

/// The unique undirected edges (i < j) of the faces, sorted by (j, i): the numbering of the
/// scalable-CCD data.
inline std::vector<std::array<std::uint32_t, 2>> unique_edges(
    const std::vector<std::array<std::uint32_t, 3>>& faces) {
  std::vector<std::array<std::uint32_t, 2>> edges;
  edges.reserve(faces.size() * 3);
  for (const auto& f : faces) {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t a = f[static_cast<std::size_t>(k)];
      std::uint32_t b = f[static_cast<std::size_t>((k + 1) % 3)];
      if (a > b) std::swap(a, b);
      edges.push_back({a, b});
    }
  }
  std::sort(edges.begin(), edges.end(),
            [](const auto& x, const auto& y) { return x[1] != y[1] ? x[1] < y[1] : x[0] < y[0]; });
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

}  // namespace tetseg::test::ccd_io
