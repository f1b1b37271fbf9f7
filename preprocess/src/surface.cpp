// Boundary extraction and volumes. No CGAL here.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tetseg/preprocess/surface.hpp"
#include "validate_internal.hpp"
#include "vec3_math.hpp"

#if defined(TETSEG_HAVE_OPENMP)
#include <omp.h>
#endif

namespace tetseg::preprocess {
namespace {

// Faces of a positively oriented tet, wound so that the normal points away from the opposite
// vertex (index = the opposite vertex).
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

using FaceKey = std::array<std::uint32_t, 3>;

FaceKey sorted_face(const Tet& tet, int f) {
  std::uint32_t a = tet[kFace[f][0]], b = tet[kFace[f][1]], c = tet[kFace[f][2]];
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return {a, b, c};
}

/// A face: its sorted node ids and its id (4 x tet + local face).
struct FaceEntry {
  std::uint32_t low, mid, high, face;
};

/// Slot of a face in a block's hash table of 2^bits slots.
std::size_t face_hash(const FaceEntry& e, unsigned bits) {
  std::uint64_t h = e.low * 0x9E3779B97F4A7C15ull ^ e.mid * 0xC2B2AE3D27D4EB4Full ^
                    e.high * 0x165667B19E3779F9ull;
  h ^= h >> 29;
  return static_cast<std::size_t>((h * 0xBF58476D1CE4E5B9ull) >> (64 - bits));
}

bool same_face(const FaceEntry& x, const FaceEntry& y) {
  return x.low == y.low && x.mid == y.mid && x.high == y.high;
}

/// The checks of tet t for validate_tet_mesh, added to `checks`: node ids in range (nodes
/// marked in `used`), then degenerate or inverted. Prefetches the nodes of a tet a few ahead
/// (below `end`): the nodes of consecutive tets are rarely near each other in memory.
void check_tet(const TetMesh& mesh, std::size_t t, std::size_t end, std::vector<char>& used,
               detail::TetChecks& checks) {
  const std::size_t n = mesh.nodes.size();
  constexpr std::size_t kAhead = 6;
#if defined(__GNUC__)
  if (t + kAhead < end)
    for (std::uint32_t v : mesh.tets[t + kAhead])
      if (v < n) __builtin_prefetch(mesh.nodes[v].data());
#endif
  const Tet& tet = mesh.tets[t];
  if (tet[0] >= n || tet[1] >= n || tet[2] >= n || tet[3] >= n) {
    checks.first_out_of_range = std::min(checks.first_out_of_range, t);
    return;
  }
  for (std::uint32_t v : tet) {
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp atomic write
#endif
    used[v] = 1;
  }
  const Vec3& a = mesh.nodes[tet[0]];
  const Vec3& b = mesh.nodes[tet[1]];
  const Vec3& c = mesh.nodes[tet[2]];
  const Vec3& d = mesh.nodes[tet[3]];
  const double det = detail::tet_det(a, b, c, d);
  // sqrt of the largest squared edge: the same double as the largest of the six lengths.
  const double edge = std::sqrt(
      std::max({detail::distance2(a, b), detail::distance2(a, c), detail::distance2(a, d),
                detail::distance2(b, c), detail::distance2(b, d), detail::distance2(c, d)}));
  if (!(std::abs(det) > detail::kDegenerateTetVolume * edge * edge * edge)) {
    if (checks.degenerate++ == 0) checks.first_degenerate = t;
  } else if (det < 0) {
    if (checks.inverted++ == 0) checks.first_inverted = t;
  }
}

int thread_count() {
#if defined(TETSEG_HAVE_OPENMP)
  return omp_get_max_threads();
#else
  return 1;
#endif
}

}  // namespace

detail::FaceMatch detail::match_faces(const TetMesh& mesh, bool check_tets) {
  // No comparison sort of the 4 T faces: a counting sort into blocks of 1024 smallest-node ids
  // (one streaming scatter, a write stream per block), then a hash table per block, in cache.
  // Faces whose nodes are all out of range share a last block. Threads split the tets for the
  // counting (and the tet checks) and the scatter, and the blocks for the rest; the result
  // does not depend on their number.
  const std::vector<Tet>& tets = mesh.tets;
  if (tets.size() >= (std::size_t{1} << 30))
    throw std::length_error("match_faces: 2^30 tets or more");
  constexpr unsigned kFineBits = 10;
  const std::size_t node_count = mesh.nodes.size();
  const std::size_t out_of_range_block = (node_count >> kFineBits) + 1;
  const std::size_t block_count = out_of_range_block + 1;
  auto entry_of = [&](std::size_t t, int f) {
    const FaceKey key = sorted_face(tets[t], f);
    return FaceEntry{key[0], key[1], key[2], static_cast<std::uint32_t>(4 * t + f)};
  };
  auto block_of = [&](const FaceEntry& e) -> std::size_t {
    return e.low < node_count ? e.low >> kFineBits : out_of_range_block;
  };

  // Scatter into blocks: part p (a contiguous range of tets) writes its faces of block b from
  // start[b * parts + p] on, so every part can run on its own thread.
  const std::size_t parts = static_cast<std::size_t>(std::max(1, thread_count()));
  auto part_begin = [&](std::size_t p) { return tets.size() * p / parts; };
  std::vector<std::size_t> start(block_count * parts + 1, 0);
  const std::int64_t part_count = static_cast<std::int64_t>(parts);
  std::vector<TetChecks> part_checks(parts);
  std::vector<char> used(check_tets ? node_count : 0, 0);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(static, 1)
#endif
  for (std::int64_t pi = 0; pi < part_count; ++pi) {
    const std::size_t p = static_cast<std::size_t>(pi);
    const std::size_t end = part_begin(p + 1);
    TetChecks checks;
    for (std::size_t t = part_begin(p); t < end; ++t) {
      for (int f = 0; f < 4; ++f) ++start[block_of(entry_of(t, f)) * parts + p + 1];
      if (check_tets) check_tet(mesh, t, end, used, checks);
    }
    part_checks[p] = checks;
  }
  FaceMatch match;
  if (check_tets) {
    match.tets_checked = true;
    TetChecks& all = match.tets;
    for (const TetChecks& c : part_checks) {  // parts ascend by tet
      all.first_out_of_range = std::min(all.first_out_of_range, c.first_out_of_range);
      all.degenerate += c.degenerate;
      all.inverted += c.inverted;
      all.first_degenerate = std::min(all.first_degenerate, c.first_degenerate);
      all.first_inverted = std::min(all.first_inverted, c.first_inverted);
    }
    all.unused = static_cast<std::size_t>(std::count(used.begin(), used.end(), 0));
    all.first_unused =
        static_cast<std::uint32_t>(std::find(used.begin(), used.end(), 0) - used.begin());
  }
  for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
  // Left uninitialised: the scatter's threads write every entry, and so touch its pages first.
  const std::unique_ptr<FaceEntry[]> entries(new FaceEntry[tets.size() * 4]);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(static, 1)
#endif
  for (std::int64_t pi = 0; pi < part_count; ++pi) {
    const std::size_t p = static_cast<std::size_t>(pi);
    std::vector<std::size_t> next(block_count);
    for (std::size_t b = 0; b < block_count; ++b) next[b] = start[b * parts + p];
    for (std::size_t t = part_begin(p); t < part_begin(p + 1); ++t)
      for (int f = 0; f < 4; ++f) {
        const FaceEntry e = entry_of(t, f);
        entries[next[block_of(e)]++] = e;
      }
  }

  // Count each block's faces in a hash table (open addressing, at most half full, in cache
  // for the usual 1024 nodes' 25,000 faces): a face seen once is on the boundary.
  std::vector<std::vector<std::uint32_t>> block_boundary(block_count);
  std::vector<std::size_t> block_crowded(block_count, 0);
  std::vector<FaceKey> block_first_crowded(block_count);
  const std::int64_t blocks = static_cast<std::int64_t>(block_count);
  const bool find_roots = check_tets && match.tets.first_out_of_range == SIZE_MAX;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    // The components of validation: one thread finds them, the others start on the blocks.
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp single nowait
#endif
    if (find_roots) match.node_roots = tet_node_roots(mesh);
    struct Slot {
      std::uint32_t entry;  // index in the block; kEmpty when free
      std::uint32_t count;
    };
    constexpr std::uint32_t kEmpty = UINT32_MAX;
    std::vector<Slot> table;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 8)
#endif
    for (std::int64_t bi = 0; bi < blocks; ++bi) {
      const std::size_t b = static_cast<std::size_t>(bi);
      const FaceEntry* const first = entries.get() + start[b * parts];
      const std::size_t size = start[(b + 1) * parts] - start[b * parts];
      if (size == 0) continue;
      unsigned bits = 4;
      while ((std::size_t{1} << bits) < 2 * size) ++bits;
      const std::size_t slot_mask = (std::size_t{1} << bits) - 1;
      table.assign(std::size_t{1} << bits, Slot{kEmpty, 0});
      for (std::size_t i = 0; i < size; ++i) {
        std::size_t h = face_hash(first[i], bits);
        while (table[h].entry != kEmpty && !same_face(first[table[h].entry], first[i]))
          h = (h + 1) & slot_mask;
        if (table[h].entry == kEmpty) table[h].entry = static_cast<std::uint32_t>(i);
        ++table[h].count;
      }
      for (const Slot& slot : table) {
        if (slot.count == 1) {
          block_boundary[b].push_back(first[slot.entry].face);
        } else if (slot.count > 2) {
          const FaceEntry& e = first[slot.entry];
          const FaceKey key = {e.low, e.mid, e.high};
          if (block_crowded[b]++ == 0 || key < block_first_crowded[b]) block_first_crowded[b] = key;
        }
      }
    }
  }

  match.boundary.assign(tets.size(), 0);
  for (std::size_t b = 0; b < block_count; ++b) {
    for (std::uint32_t face : block_boundary[b])
      match.boundary[face / 4] |= static_cast<std::uint8_t>(1u << (face % 4));
    // Blocks ascend by smallest node: the first block with a crowded face has the smallest.
    if (block_crowded[b] > 0 && match.crowded == 0) match.first_crowded = block_first_crowded[b];
    match.crowded += block_crowded[b];
  }
  return match;
}

Surface detail::surface_from_faces(const TetMesh& mesh, const FaceMatch& match) {
  Surface surface;
  std::vector<char> on_surface(mesh.nodes.size(), 0);
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    if (match.boundary[t] == 0) continue;
    const Tet& tet = mesh.tets[t];
    for (int f = 0; f < 4; ++f) {
      if (!(match.boundary[t] & (1u << f))) continue;
      const Tri tri = {tet[kFace[f][0]], tet[kFace[f][1]], tet[kFace[f][2]]};
      surface.triangles.push_back(tri);
      for (std::uint32_t v : tri)
        if (v < on_surface.size()) on_surface[v] = 1;
    }
  }
  for (std::uint32_t v = 0; v < on_surface.size(); ++v) {
    if (on_surface[v]) {
      surface.surface_nodes.push_back(v);
    } else {
      surface.interior_nodes.push_back(v);
    }
  }
  return surface;
}

Surface extract_surface(const TetMesh& mesh) {
  return detail::surface_from_faces(mesh, detail::match_faces(mesh, false));
}

Surface detail::extract_valid_surface(const TetMesh& mesh, const std::string& file,
                                      NodeParts& parts) {
  const FaceMatch match = match_faces(mesh, true);
  Surface surface = surface_from_faces(mesh, match);
  parts = validate_tet_mesh(mesh, surface, match, file);
  return surface;
}

Surface extract_valid_surface(const TetMesh& mesh, const std::string& file) {
  detail::NodeParts parts;
  return detail::extract_valid_surface(mesh, file, parts);
}

double enclosed_volume(const std::vector<Vec3>& points, const std::vector<Tri>& triangles) {
  // Divergence theorem with the centroid as origin (less cancellation than the world origin).
  Vec3 c = {0, 0, 0};
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) c[k] += p[k];
  if (!points.empty())
    for (int k = 0; k < 3; ++k) c[k] /= static_cast<double>(points.size());
  double sum = 0.0;
  for (const Tri& t : triangles) {
    if (t[0] >= points.size() || t[1] >= points.size() || t[2] >= points.size()) continue;
    const Vec3& a = points[t[0]];
    const Vec3& b = points[t[1]];
    const Vec3& d = points[t[2]];
    const double u[3] = {a[0] - c[0], a[1] - c[1], a[2] - c[2]};
    const double v[3] = {b[0] - c[0], b[1] - c[1], b[2] - c[2]};
    const double w[3] = {d[0] - c[0], d[1] - c[1], d[2] - c[2]};
    sum += u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
  }
  return sum / 6.0;
}

double total_tet_volume(const TetMesh& mesh) {
  double sum = 0.0;
  const std::size_t n = mesh.nodes.size();
  for (const Tet& t : mesh.tets) {
    if (t[0] >= n || t[1] >= n || t[2] >= n || t[3] >= n) continue;
    const Vec3& a = mesh.nodes[t[0]];
    const Vec3& b = mesh.nodes[t[1]];
    const Vec3& c = mesh.nodes[t[2]];
    const Vec3& d = mesh.nodes[t[3]];
    sum += detail::tet_det(a, b, c, d);
  }
  return sum / 6.0;
}

}  // namespace tetseg::preprocess
