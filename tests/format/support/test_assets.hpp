#pragma once
// Hand-built assets and byte-level helpers shared by the format and runtime tests. Everything
// here is computed independently of the library: the layout offsets follow docs/format.md and
// the CRC-32C is a plain bitwise implementation.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/format/asset_io.hpp"

namespace tetseg::test {

using format::Asset;
using format::BodyKind;
using format::BvhNode;
using format::Cluster;
using format::DetectorForm;
using format::DetectorPoint;
using format::DetectorTerm;
using format::kClusterOverlapOnly;
using format::kNoTet;
using format::minor_version_needed;
using format::Triangle;
using Vec3 = std::array<double, 3>;

// ---- envelope byte table (docs/format.md) ----
inline constexpr std::size_t kMajorAt = 8;
inline constexpr std::size_t kMinorAt = 10;
inline constexpr std::size_t kHeaderSizeAt = 12;
inline constexpr std::size_t kFlagsAt = 16;
inline constexpr std::size_t kPayloadSizeAt = 20;
inline constexpr std::size_t kPayloadCrcAt = 28;
inline constexpr std::size_t kHeaderCrcAt = 32;
inline constexpr std::size_t kHeaderBytes = 36;

/// Bitwise CRC-32C (reflected 0x82F63B78), independent of the library's table version.
inline std::uint32_t crc32c_bitwise(const std::uint8_t* data, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc & 1u) ? (crc >> 1) ^ 0x82F63B78u : crc >> 1;
  }
  return ~crc;
}

inline std::uint64_t get_le(const std::vector<std::uint8_t>& b, std::size_t at, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= std::uint64_t(b[at + i]) << (8 * i);
  return v;
}

inline void put_le(std::vector<std::uint8_t>& b, std::size_t at, std::uint64_t v, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

/// Recomputes the header checksum only (after editing a header field).
inline void reseal_header(std::vector<std::uint8_t>& b) {
  put_le(b, kHeaderCrcAt, crc32c_bitwise(b.data(), kHeaderCrcAt), 4);
}

/// Recomputes payload size, payload checksum and header checksum (after editing the payload).
inline void reseal(std::vector<std::uint8_t>& b) {
  const std::size_t payload = b.size() - kHeaderBytes;
  put_le(b, kPayloadSizeAt, payload, 8);
  put_le(b, kPayloadCrcAt, crc32c_bitwise(b.data() + kHeaderBytes, payload), 4);
  reseal_header(b);
}

/// Offsets, relative to the payload start, of every size tag (u64) in the payload of `a`,
/// computed from the documented field order. Names match docs/format.md.
inline std::vector<std::pair<std::string, std::size_t>> payload_size_tags(const Asset& a) {
  std::vector<std::pair<std::string, std::size_t>> tags;
  const std::uint16_t minor = minor_version_needed(a);
  std::size_t at = 1 + 4;       // endianness tag, node_count
  if (minor >= 2) at += 4 + 4;  // body_kind, detector_form
  auto tag = [&](const char* name, std::size_t n, std::size_t element_bytes) {
    tags.emplace_back(name, at);
    at += 8 + n * element_bytes;
  };
  tag("rest_positions", a.rest_positions.size(), 24);
  tag("triangles", a.triangles.size(), 12);
  tag("triangle_cluster", a.triangle_cluster.size(), 4);
  tag("clusters", a.clusters.size(), minor == 0 ? 24 : minor == 1 ? 76 : 108);
  tag("cluster_triangles", a.cluster_triangles.size(), 4);
  tag("bvh_nodes", a.bvh_nodes.size(), 12);
  tag("boundaries", a.boundaries.size(), 8);
  tag("boundary_nodes", a.boundary_nodes.size(), 4);
  if (minor >= 2) {
    tag("detector_terms", a.detector_terms.size(), 12);
    tags.emplace_back("bone_names", at);
    at += 8;
    for (const std::string& name : a.bone_names) tag("bone name", name.size(), 1);
    tag("source_vertex_nodes", a.source_vertex_nodes.size(), 4);
  }
  tag("provenance.tool_version", a.provenance.tool_version.size(), 1);
  tag("provenance.source", a.provenance.source.size(), 1);
  tags.emplace_back("provenance.options", at);
  at += 8;
  for (const auto& [k, v] : a.provenance.options) {
    tag("option key", k.size(), 1);
    tag("option value", v.size(), 1);
  }
  tags.emplace_back("end", at);
  return tags;
}

// ---- asset construction ----

/// BVH topology over `count` cluster-local triangle positions: median split, leaves of at
/// most `leaf_size`, pre-order (children always after their parent).
inline void build_bvh(std::uint32_t first, std::uint32_t count, std::uint32_t leaf_size,
                      std::vector<BvhNode>& nodes) {
  const std::size_t self = nodes.size();
  nodes.push_back({});
  if (count <= leaf_size) {
    nodes[self] = BvhNode{first, 0, count};
    return;
  }
  const std::uint32_t left = count / 2;
  const auto left_index = static_cast<std::uint32_t>(nodes.size());
  build_bvh(first, left, leaf_size, nodes);
  const auto right_index = static_cast<std::uint32_t>(nodes.size());
  build_bvh(first + left, count - left, leaf_size, nodes);
  nodes[self] = BvhNode{left_index, right_index, 0};
}

inline Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// Rest position of a cluster's detector (kTetPoint: evaluated from the rest positions; other
/// forms: `detector_rest`).
inline Vec3 detector_position(const Asset& a, const Cluster& c) {
  return format::rest_detector_position(a, c);
}

/// Share of the cluster's triangles whose outward normal faces away from the detector.
inline float positive_fraction(const Asset& a, const Cluster& c) {
  const Vec3 d = detector_position(a, c);
  std::uint32_t positive = 0;
  for (std::uint32_t i = 0; i < c.triangle_count; ++i) {
    const Triangle& t = a.triangles[a.cluster_triangles[c.triangle_offset + i]];
    const Vec3& p0 = a.rest_positions[t[0]];
    const Vec3 n = cross(sub(a.rest_positions[t[1]], p0), sub(a.rest_positions[t[2]], p0));
    if (dot(n, sub(p0, d)) > 0) ++positive;
  }
  return static_cast<float>(positive) / static_cast<float>(c.triangle_count);
}

/// Appends a cluster over the given surface triangles (in BVH leaf order).
inline void add_cluster(Asset& a, const DetectorPoint& detector,
                        const std::vector<std::uint32_t>& tris, std::uint32_t leaf_size,
                        std::uint32_t flags = 0) {
  Cluster c;
  c.detector = detector;
  c.flags = flags;
  c.triangle_offset = static_cast<std::uint32_t>(a.cluster_triangles.size());
  c.triangle_count = static_cast<std::uint32_t>(tris.size());
  c.bvh_offset = static_cast<std::uint32_t>(a.bvh_nodes.size());
  std::vector<BvhNode> nodes;
  build_bvh(0, c.triangle_count, leaf_size, nodes);
  c.bvh_count = static_cast<std::uint32_t>(nodes.size());
  a.bvh_nodes.insert(a.bvh_nodes.end(), nodes.begin(), nodes.end());
  const auto id = static_cast<std::uint32_t>(a.clusters.size());
  a.triangle_cluster.resize(a.triangles.size());
  for (std::uint32_t t : tris) {
    a.cluster_triangles.push_back(t);
    a.triangle_cluster[t] = id;
  }
  a.clusters.push_back(c);
  a.clusters.back().rest_positive_fraction = positive_fraction(a, a.clusters.back());
}

inline void add_loop(Asset& a, const std::vector<std::uint32_t>& nodes) {
  a.boundaries.push_back({static_cast<std::uint32_t>(a.boundary_nodes.size()),
                          static_cast<std::uint32_t>(nodes.size())});
  a.boundary_nodes.insert(a.boundary_nodes.end(), nodes.begin(), nodes.end());
}

/// The golden asset: the surface of an octahedral tet mesh (6 surface nodes, 2 interior
/// nodes on the z axis, tets fanning from them), split at the equator into two clusters, each
/// culled from the interior node on its side. One boundary loop: the equator.
/// The octahedron with its two clusters: upper half (7 BVH nodes, one triangle per leaf) and
/// lower half (3, two triangles per leaf), seen from `upper` and `lower`.
inline Asset make_octahedron(const DetectorPoint& upper, const DetectorPoint& lower,
                             std::uint32_t lower_flags = 0) {
  Asset a;
  a.rest_positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},    {0, -1, 0},
                      {0, 0, 1}, {0, 0, -1}, {0, 0, 0.25}, {0, 0, -0.25}};
  a.node_count = 8;
  // +x=0 -x=1 +y=2 -y=3 +z=4 -z=5, wound outward.
  a.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                 {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  add_cluster(a, upper, {0, 1, 2, 3}, 1);
  add_cluster(a, lower, {6, 7, 4, 5}, 2, lower_flags);
  add_loop(a, {0, 2, 1, 3});
  a.provenance.tool_version = "tetseg 0.1.0";
  a.provenance.source = "octahedron.off";
  a.provenance.options = {{"clusters", "2"}, {"detector", "interior"}, {"leaf_size", "1,2"}};
  return a;
}

inline Asset make_octahedron_asset() {
  return make_octahedron(DetectorPoint::at_node(6), DetectorPoint::at_node(7));
}

/// The golden asset of version 1.1: the octahedron's surface with the upper cluster seen from
/// a point inside tet 0 = (6, 0, 2, 4) and the lower cluster flagged overlap-only, its
/// detector the centroid of tet 9 = (6, 7, 1, 3) (a tet of the same octahedral mesh).
inline Asset make_octahedron_asset_v11() {
  DetectorPoint upper;
  upper.nodes = {6, 0, 2, 4};
  upper.weights = {0.625, 0.125, 0.125, 0.125};
  upper.tet = 0;
  DetectorPoint lower;
  lower.nodes = {6, 7, 1, 3};
  lower.weights = {0.25, 0.25, 0.25, 0.25};
  lower.tet = 9;
  return make_octahedron(upper, lower, kClusterOverlapOnly);
}

/// Gives cluster `c` (called in cluster order, after every earlier cluster's terms) the
/// detector `terms` at rest position `rest`, and recomputes its rest_positive_fraction.
inline void set_detector_terms(Asset& a, std::size_t c, const std::vector<DetectorTerm>& terms,
                               const Vec3& rest) {
  Cluster& cl = a.clusters[c];
  cl.detector_term_offset = static_cast<std::uint32_t>(a.detector_terms.size());
  cl.detector_term_count = static_cast<std::uint32_t>(terms.size());
  cl.detector_rest = rest;
  a.detector_terms.insert(a.detector_terms.end(), terms.begin(), terms.end());
  cl.rest_positive_fraction = positive_fraction(a, cl);
}

/// The golden assets of version 1.2: the octahedron as a surface body (no interior nodes; node
/// 6 is a vertex no triangle uses, as an input surface may have), same clusters and loop.
/// kSurfaceWeights: the upper cluster seen from (0, 0, 0.5) = 1/8 of each equator vertex + 1/2
/// of the top, the lower one from (0, 0, -0.5) = 1/4 of +x and -x + 1/2 of the bottom.
/// kBones: bones "root", "spine", "head"; the upper detector at (0, 0, 0.5) carried 3/4 by
/// "spine" and 1/4 by "head"; the lower cluster overlap-only without terms, at (0, 0, -0.5).
/// The weights asset was read from a file of 9 vertices split at seams (source_vertex_nodes:
/// the top and +x stored twice, the file's order not the nodes'); the bones one has no map.
inline Asset make_surface_octahedron_v12(DetectorForm form) {
  Asset a = make_octahedron(DetectorPoint::at_node(0), DetectorPoint::at_node(0));
  a.rest_positions.resize(6);
  a.rest_positions.push_back({3, 3, 3});
  a.node_count = 7;
  a.body_kind = BodyKind::kSurface;
  a.detector_form = form;
  if (form == DetectorForm::kBones) {
    a.bone_names = {"root", "spine", "head"};
    set_detector_terms(a, 0, {{1, 0.75}, {2, 0.25}}, {0, 0, 0.5});
    a.clusters[1].flags = kClusterOverlapOnly;
    set_detector_terms(a, 1, {}, {0, 0, -0.5});
  } else {
    set_detector_terms(a, 0, {{0, 0.125}, {2, 0.125}, {1, 0.125}, {3, 0.125}, {4, 0.5}},
                       {0, 0, 0.5});
    set_detector_terms(a, 1, {{5, 0.5}, {0, 0.25}, {1, 0.25}}, {0, 0, -0.5});
    a.source_vertex_nodes = {4, 0, 1, 2, 3, 4, 5, 6, 0};
  }
  a.provenance.source = "octahedron.obj";
  a.provenance.options = {{"body", "surface"},
                          {"detectors", form == DetectorForm::kBones ? "skin" : "weights"}};
  return a;
}

/// A larger asset: the surface of the cube [-1,1]^3 with an n x n grid per face (shared
/// nodes on edges), one cluster per face with its own interior detector node, and the
/// perimeter of every face as a boundary loop.
inline Asset make_cube_asset(std::uint32_t n) {
  Asset a;
  std::map<std::array<std::uint32_t, 3>, std::uint32_t> ids;
  auto node = [&](std::array<std::uint32_t, 3> g) {
    auto it = ids.find(g);
    if (it != ids.end()) return it->second;
    const auto id = static_cast<std::uint32_t>(a.rest_positions.size());
    ids.emplace(g, id);
    a.rest_positions.push_back(
        {-1.0 + 2.0 * g[0] / n, -1.0 + 2.0 * g[1] / n, -1.0 + 2.0 * g[2] / n});
    return id;
  };
  std::vector<std::vector<std::uint32_t>> face_tris(6);
  std::vector<std::vector<std::uint32_t>> face_loops(6);
  for (std::uint32_t f = 0; f < 6; ++f) {
    const std::uint32_t axis = f / 2;
    const bool high = f % 2 == 1;
    const std::uint32_t u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
    auto grid = [&](std::uint32_t i, std::uint32_t j) {
      std::array<std::uint32_t, 3> g{};
      g[axis] = high ? n : 0;
      g[u_axis] = i;
      g[v_axis] = j;
      return node(g);
    };
    for (std::uint32_t i = 0; i < n; ++i) {
      for (std::uint32_t j = 0; j < n; ++j) {
        const std::uint32_t p00 = grid(i, j), p10 = grid(i + 1, j), p11 = grid(i + 1, j + 1),
                            p01 = grid(i, j + 1);
        // (u, v, axis) is right-handed, so u x v points along +axis.
        std::array<Triangle, 2> quad = {Triangle{p00, p10, p11}, Triangle{p00, p11, p01}};
        for (Triangle t : quad) {
          if (!high) std::swap(t[1], t[2]);
          face_tris[f].push_back(static_cast<std::uint32_t>(a.triangles.size()));
          a.triangles.push_back(t);
        }
      }
    }
    for (std::uint32_t i = 0; i < n; ++i) face_loops[f].push_back(grid(i, 0));
    for (std::uint32_t j = 0; j < n; ++j) face_loops[f].push_back(grid(n, j));
    for (std::uint32_t i = n; i > 0; --i) face_loops[f].push_back(grid(i, n));
    for (std::uint32_t j = n; j > 0; --j) face_loops[f].push_back(grid(0, j));
  }
  const auto surface_nodes = static_cast<std::uint32_t>(a.rest_positions.size());
  for (std::uint32_t f = 0; f < 6; ++f) {
    Vec3 d{0, 0, 0};
    d[f / 2] = f % 2 == 1 ? 0.5 : -0.5;
    a.rest_positions.push_back(d);
  }
  a.node_count = static_cast<std::uint32_t>(a.rest_positions.size());
  for (std::uint32_t f = 0; f < 6; ++f) {
    std::vector<std::uint32_t> leaf_order(face_tris[f].rbegin(), face_tris[f].rend());
    add_cluster(a, DetectorPoint::at_node(surface_nodes + f), leaf_order, f % 3 + 1);
    add_loop(a, face_loops[f]);
  }
  a.provenance.tool_version = "tetseg 0.1.0";
  a.provenance.source = "cube.off";
  a.provenance.options = {{"grid", std::to_string(n)}, {"segments", "6"}};
  return a;
}

/// Field-by-field equality; floats compared bitwise.
inline bool same_bits(double x, double y) {
  return std::memcmp(&x, &y, sizeof x) == 0;
}
inline bool same_bits(float x, float y) {
  return std::memcmp(&x, &y, sizeof x) == 0;
}

inline bool assets_equal(const Asset& a, const Asset& b) {
  if (a.node_count != b.node_count || a.rest_positions.size() != b.rest_positions.size())
    return false;
  for (std::size_t i = 0; i < a.rest_positions.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!same_bits(a.rest_positions[i][k], b.rest_positions[i][k])) return false;
  if (a.triangles != b.triangles || a.triangle_cluster != b.triangle_cluster) return false;
  if (a.clusters.size() != b.clusters.size()) return false;
  for (std::size_t i = 0; i < a.clusters.size(); ++i) {
    const Cluster& x = a.clusters[i];
    const Cluster& y = b.clusters[i];
    if (x.detector.nodes != y.detector.nodes || x.detector.tet != y.detector.tet ||
        x.flags != y.flags)
      return false;
    for (int k = 0; k < 4; ++k)
      if (!same_bits(x.detector.weights[k], y.detector.weights[k])) return false;
    if (!same_bits(x.rest_positive_fraction, y.rest_positive_fraction) ||
        x.triangle_offset != y.triangle_offset || x.triangle_count != y.triangle_count ||
        x.bvh_offset != y.bvh_offset || x.bvh_count != y.bvh_count ||
        x.detector_term_offset != y.detector_term_offset ||
        x.detector_term_count != y.detector_term_count)
      return false;
    for (int k = 0; k < 3; ++k)
      if (!same_bits(x.detector_rest[k], y.detector_rest[k])) return false;
  }
  if (a.body_kind != b.body_kind || a.detector_form != b.detector_form ||
      a.bone_names != b.bone_names || a.detector_terms.size() != b.detector_terms.size() ||
      a.source_vertex_nodes != b.source_vertex_nodes)
    return false;
  for (std::size_t i = 0; i < a.detector_terms.size(); ++i) {
    if (a.detector_terms[i].index != b.detector_terms[i].index ||
        !same_bits(a.detector_terms[i].weight, b.detector_terms[i].weight))
      return false;
  }
  if (a.cluster_triangles != b.cluster_triangles || a.bvh_nodes.size() != b.bvh_nodes.size())
    return false;
  for (std::size_t i = 0; i < a.bvh_nodes.size(); ++i) {
    const BvhNode& x = a.bvh_nodes[i];
    const BvhNode& y = b.bvh_nodes[i];
    if (x.first != y.first || x.second != y.second || x.count != y.count) return false;
  }
  if (a.boundaries.size() != b.boundaries.size()) return false;
  for (std::size_t i = 0; i < a.boundaries.size(); ++i) {
    if (a.boundaries[i].node_offset != b.boundaries[i].node_offset ||
        a.boundaries[i].node_count != b.boundaries[i].node_count)
      return false;
  }
  return a.boundary_nodes == b.boundary_nodes &&
         a.provenance.tool_version == b.provenance.tool_version &&
         a.provenance.source == b.provenance.source && a.provenance.options == b.provenance.options;
}

inline bool is_empty(const Asset& a) {
  return assets_equal(a, Asset{});
}

/// The committed golden asset of version 1.`minor` (`variant`: e.g. "-bones").
inline std::string golden_path(int minor = 0, const std::string& variant = "") {
  return std::string(TETSEG_SOURCE_DIR) + "/tests/golden/asset-v1." + std::to_string(minor) +
         variant + ".tetseg";
}

inline std::vector<std::uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<std::uint8_t>(std::istreambuf_iterator<char>(in),
                                   std::istreambuf_iterator<char>());
}

}  // namespace tetseg::test
