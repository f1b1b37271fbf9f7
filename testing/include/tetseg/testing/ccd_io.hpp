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

#include "mesh_io.hpp"

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

/// Reads a PLY triangle soup through the tools' mesh I/O layer (tetseg_mesh_io: ascii,
/// binary little or big endian, any scalar types, extra properties skipped). Throws
/// std::runtime_error on malformed input and on faces that are not triangles.
inline Mesh read_ply(const std::string& path) {
  io::PlyMesh ply;
  const io::IoStatus read = io::read_ply(path, ply);
  if (!read.ok()) throw std::runtime_error(read.error);
  Mesh mesh;
  mesh.vertices.assign(ply.vertices.begin(), ply.vertices.end());
  for (const auto& face : ply.faces) {
    if (face.size() != 3) throw std::runtime_error("face is not a triangle");
    mesh.faces.push_back({face[0], face[1], face[2]});
  }
  if (!ply.faces.empty() && ply.vertices.empty()) throw std::runtime_error("no vertices");
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
