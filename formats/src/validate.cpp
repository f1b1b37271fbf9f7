// Semantic validation of a decoded asset (docs/format.md, "Validation rules"). Every
// allocation here is bounded by the sizes of vectors that already exist, never by a scalar
// read from the file (node_count in particular is never used to size anything).
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "tetseg/format/asset_io.hpp"

namespace tetseg::format {
namespace {

struct Invalid {
  std::string message;
};

[[noreturn]] void fail(std::string message) {
  throw Invalid{std::move(message)};
}

std::string at(const char* what, std::size_t i) {
  return std::string(what) + "[" + std::to_string(i) + "]";
}

std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  if (a > b) std::swap(a, b);
  return (std::uint64_t(a) << 32) | b;
}

void check_limits(const Asset& a) {
  auto limit = [](const char* what, std::size_t n, std::uint64_t max) {
    if (n > max) {
      fail(std::string(what) + " has " + std::to_string(n) + " entries, the limit is " +
           std::to_string(max));
    }
  };
  limit("node_count", a.node_count, kMaxNodes);
  limit("rest_positions", a.rest_positions.size(), kMaxNodes);
  limit("triangles", a.triangles.size(), kMaxTriangles);
  limit("triangle_cluster", a.triangle_cluster.size(), kMaxTriangles);
  limit("clusters", a.clusters.size(), kMaxClusters);
  limit("cluster_triangles", a.cluster_triangles.size(), kMaxTriangles);
  limit("bvh_nodes", a.bvh_nodes.size(), kMaxBvhNodes);
  limit("boundaries", a.boundaries.size(), kMaxBoundaryLoops);
  limit("boundary_nodes", a.boundary_nodes.size(), kMaxBoundaryNodes);
  limit("detector_terms", a.detector_terms.size(), std::uint64_t(kMaxClusters) * kMaxDetectorTerms);
  limit("bone_names", a.bone_names.size(), kMaxBones);
  for (const std::string& name : a.bone_names) limit("bone name", name.size(), kMaxStringBytes);
  limit("source_vertex_nodes", a.source_vertex_nodes.size(), kMaxSourceVertices);
  limit("provenance.tool_version", a.provenance.tool_version.size(), kMaxStringBytes);
  limit("provenance.source", a.provenance.source.size(), kMaxStringBytes);
  limit("provenance.options", a.provenance.options.size(), kMaxProvenanceOptions);
  for (std::size_t i = 0; i < a.provenance.options.size(); ++i) {
    limit("provenance option key", a.provenance.options[i].first.size(), kMaxStringBytes);
    limit("provenance option value", a.provenance.options[i].second.size(), kMaxStringBytes);
    if (i > 0 && !(a.provenance.options[i - 1].first < a.provenance.options[i].first)) {
      fail("provenance options are not sorted by unique key at " + std::to_string(i));
    }
  }
}

void check_nodes_and_triangles(const Asset& a) {
  if (!a.rest_positions.empty()) {
    if (a.rest_positions.size() != a.node_count) {
      fail("rest_positions has " + std::to_string(a.rest_positions.size()) +
           " entries, node_count is " + std::to_string(a.node_count));
    }
    for (std::size_t i = 0; i < a.rest_positions.size(); ++i) {
      for (double x : a.rest_positions[i]) {
        if (!std::isfinite(x)) fail(at("rest_positions", i) + " is not finite");
      }
    }
  }
  if (a.triangles.empty()) fail("asset has no surface triangles");
  for (std::size_t t = 0; t < a.triangles.size(); ++t) {
    const Triangle& tri = a.triangles[t];
    for (std::uint32_t v : tri) {
      if (v >= a.node_count) {
        fail(at("triangles", t) + " has node " + std::to_string(v) + " >= node_count " +
             std::to_string(a.node_count));
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      fail(at("triangles", t) + " repeats a node id");
    }
  }
}

/// A cluster's flags are known. kTetPoint: its detector is in node form or point form
/// (asset.hpp, DetectorPoint), its ids below node_count. Whether a point-form detector lies
/// inside the body is not checked (the asset stores no tets); the runtime is correct for any
/// detector point. Other forms: the unused detector is the node form at node 0, no tet id.
void check_detector_point(const Asset& a, std::size_t c) {
  const Cluster& cl = a.clusters[c];
  const DetectorPoint& d = cl.detector;
  if ((cl.flags & ~kKnownClusterFlags) != 0) {
    fail(at("clusters", c) + ".flags has unknown bits " + std::to_string(cl.flags));
  }
  if (a.detector_form != DetectorForm::kTetPoint) {
    if (!d.is_node() || d.nodes[0] != 0 || d.tet != kNoTet)
      fail(at("clusters", c) +
           ".detector is not the unused node form at node 0 (the detector form is not kTetPoint)");
    return;
  }
  for (std::uint32_t id : d.nodes) {
    if (id >= a.node_count) {
      fail(at("clusters", c) + ".detector node " + std::to_string(id) + " >= node_count " +
           std::to_string(a.node_count));
    }
  }
  if (d.is_node()) return;
  for (int i = 0; i < 4; ++i) {
    for (int j = i + 1; j < 4; ++j) {
      if (d.nodes[i] == d.nodes[j]) {
        fail(at("clusters", c) + ".detector repeats node " + std::to_string(d.nodes[i]) +
             " (point form needs four distinct nodes; node form four equal ids and weights 1, 0, "
             "0, 0)");
      }
    }
  }
  double sum = 0.0;
  for (double w : d.weights) {
    if (!std::isfinite(w) || w < 0.0) {
      fail(at("clusters", c) + ".detector weight " + std::to_string(w) +
           " is not a finite non-negative value");
    }
    sum += w;
  }
  if (!(std::fabs(sum - 1.0) <= kDetectorWeightSumTolerance)) {
    fail(at("clusters", c) + ".detector weights sum to " + std::to_string(sum) + ", not 1 within " +
         std::to_string(kDetectorWeightSumTolerance));
  }
}

/// Clusters are contiguous, in order, and partition the triangles; triangle_cluster agrees.
void check_partition(const Asset& a) {
  const std::size_t tri_count = a.triangles.size();
  if (a.clusters.empty()) fail("asset has triangles but no clusters");
  if (a.triangle_cluster.size() != tri_count) {
    fail("triangle_cluster has " + std::to_string(a.triangle_cluster.size()) + " entries for " +
         std::to_string(tri_count) + " triangles");
  }
  if (a.cluster_triangles.size() != tri_count) {
    fail("cluster_triangles has " + std::to_string(a.cluster_triangles.size()) + " entries for " +
         std::to_string(tri_count) + " triangles");
  }
  std::uint64_t next_triangle = 0;
  std::uint64_t next_bvh = 0;
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    const Cluster& cl = a.clusters[c];
    if (cl.triangle_count == 0) fail(at("clusters", c) + " has no triangles");
    if (cl.triangle_offset != next_triangle) {
      fail(at("clusters", c) + ".triangle_offset is " + std::to_string(cl.triangle_offset) +
           ", expected " + std::to_string(next_triangle) + " (clusters are contiguous)");
    }
    next_triangle += cl.triangle_count;
    if (next_triangle > tri_count)
      fail(at("clusters", c) + " triangle range exceeds cluster_triangles");
    if (cl.bvh_count == 0) fail(at("clusters", c) + " has no BVH nodes");
    if (cl.bvh_offset != next_bvh) {
      fail(at("clusters", c) + ".bvh_offset is " + std::to_string(cl.bvh_offset) + ", expected " +
           std::to_string(next_bvh) + " (BVHs are contiguous)");
    }
    next_bvh += cl.bvh_count;
    if (next_bvh > a.bvh_nodes.size()) fail(at("clusters", c) + " BVH range exceeds bvh_nodes");
    if (!std::isfinite(cl.rest_positive_fraction) || cl.rest_positive_fraction < 0.0f ||
        cl.rest_positive_fraction > 1.0f) {
      fail(at("clusters", c) + ".rest_positive_fraction is not a finite value in [0,1]");
    }
    check_detector_point(a, c);
  }
  if (next_triangle != tri_count)
    fail("clusters cover " + std::to_string(next_triangle) + " of " + std::to_string(tri_count) +
         " cluster_triangles entries");
  if (next_bvh != a.bvh_nodes.size())
    fail("clusters use " + std::to_string(next_bvh) + " of " + std::to_string(a.bvh_nodes.size()) +
         " BVH nodes");

  std::vector<std::uint8_t> seen(tri_count, 0);
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    const Cluster& cl = a.clusters[c];
    for (std::uint32_t i = 0; i < cl.triangle_count; ++i) {
      const std::uint32_t t = a.cluster_triangles[std::size_t(cl.triangle_offset) + i];
      if (t >= tri_count)
        fail(at("cluster_triangles", cl.triangle_offset + std::size_t(i)) + " is out of range");
      if (seen[t]) fail("triangle " + std::to_string(t) + " is in more than one cluster entry");
      seen[t] = 1;
      if (a.triangle_cluster[t] != c) {
        fail("triangle " + std::to_string(t) + " is listed in cluster " + std::to_string(c) +
             " but triangle_cluster says " + std::to_string(a.triangle_cluster[t]));
      }
    }
  }
  // Every entry of cluster_triangles was visited and entries are unique, so with
  // cluster_triangles.size() == tri_count every triangle appears exactly once.
}

/// Body kind and detector form are known and go together: kTetPoint needs a kTet body (its
/// detectors are points of tets); kSurfaceWeights and kBones may move the detectors of either
/// body kind (the runtime evaluates them the same way). kTetPoint stores no detector terms, no
/// bone names and zero term ranges and rest positions; kSurfaceWeights no bone names.
void check_body_and_form(const Asset& a) {
  const auto kind = static_cast<std::uint32_t>(a.body_kind);
  const auto form = static_cast<std::uint32_t>(a.detector_form);
  if (a.body_kind != BodyKind::kTet && a.body_kind != BodyKind::kSurface)
    fail("body_kind " + std::to_string(kind) + " is unknown");
  if (a.detector_form != DetectorForm::kTetPoint &&
      a.detector_form != DetectorForm::kSurfaceWeights && a.detector_form != DetectorForm::kBones)
    fail("detector_form " + std::to_string(form) + " is unknown");
  if (a.detector_form == DetectorForm::kTetPoint && a.body_kind != BodyKind::kTet)
    fail("detector_form kTetPoint needs body_kind kTet (a surface body has no tets)");
  if (a.detector_form != DetectorForm::kBones && !a.bone_names.empty())
    fail("bone_names has " + std::to_string(a.bone_names.size()) +
         " entries but the detector form is not kBones");
  if (a.detector_form != DetectorForm::kTetPoint) return;
  if (!a.detector_terms.empty())
    fail("detector_terms has " + std::to_string(a.detector_terms.size()) +
         " entries but the detector form is kTetPoint");
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    const Cluster& cl = a.clusters[c];
    if (cl.detector_term_offset != 0 || cl.detector_term_count != 0 ||
        cl.detector_rest != std::array<double, 3>{})
      fail(at("clusters", c) + " has a detector term range or rest position (kTetPoint: all 0)");
  }
}

/// kSurfaceWeights and kBones: each cluster's terms are contiguous in cluster order and cover
/// detector_terms exactly; 1..kMaxDetectorTerms terms (0 allowed for an overlap-only cluster);
/// indices below node_count (weights) or bone_names.size() (bones) and distinct within the
/// cluster; weights finite, >= 0, summing to 1 within kDetectorWeightSumTolerance;
/// detector_rest finite.
void check_detector_terms(const Asset& a) {
  if (a.detector_form == DetectorForm::kTetPoint) return;
  const bool bones = a.detector_form == DetectorForm::kBones;
  const std::uint64_t bound = bones ? a.bone_names.size() : a.node_count;
  const char* bound_name = bones ? "bone_names.size()" : "node_count";
  std::uint64_t next = 0;
  std::vector<std::uint32_t> ids;
  ids.reserve(kMaxDetectorTerms);
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    const Cluster& cl = a.clusters[c];
    const std::string where = at("clusters", c);
    for (double x : cl.detector_rest) {
      if (!std::isfinite(x)) fail(where + ".detector_rest is not finite");
    }
    if (cl.detector_term_offset != next) {
      fail(where + ".detector_term_offset is " + std::to_string(cl.detector_term_offset) +
           ", expected " + std::to_string(next) + " (detector terms are contiguous)");
    }
    if (cl.detector_term_count > kMaxDetectorTerms) {
      fail(where + " has " + std::to_string(cl.detector_term_count) +
           " detector terms, the limit is " + std::to_string(kMaxDetectorTerms));
    }
    if (cl.detector_term_count == 0 && !(cl.flags & kClusterOverlapOnly))
      fail(where + " has no detector terms and is not overlap-only");
    next += cl.detector_term_count;
    if (next > a.detector_terms.size()) fail(where + " detector term range exceeds detector_terms");
    const DetectorTerm* terms = a.detector_terms.data() + cl.detector_term_offset;
    ids.clear();
    double sum = 0.0;
    for (std::uint32_t i = 0; i < cl.detector_term_count; ++i) {
      const DetectorTerm& term = terms[i];
      if (term.index >= bound) {
        fail(where + " detector term " + std::to_string(i) + " has index " +
             std::to_string(term.index) + " >= " + bound_name + " " + std::to_string(bound));
      }
      if (!std::isfinite(term.weight) || term.weight < 0.0) {
        fail(where + " detector term " + std::to_string(i) + " weight " +
             std::to_string(term.weight) + " is not a finite non-negative value");
      }
      sum += term.weight;
      ids.push_back(term.index);
    }
    if (cl.detector_term_count > 0 && !(std::fabs(sum - 1.0) <= kDetectorWeightSumTolerance)) {
      fail(where + " detector term weights sum to " + std::to_string(sum) + ", not 1 within " +
           std::to_string(kDetectorWeightSumTolerance));
    }
    std::sort(ids.begin(), ids.end());
    const auto repeat = std::adjacent_find(ids.begin(), ids.end());
    if (repeat != ids.end())
      fail(where + " detector terms repeat index " + std::to_string(*repeat));
  }
  if (next != a.detector_terms.size()) {
    fail("clusters use " + std::to_string(next) + " of " + std::to_string(a.detector_terms.size()) +
         " detector_terms");
  }
}

/// source_vertex_nodes (kSurface only, optional): every entry below node_count and every node
/// hit at least once. The hit table is sized by node_count only after node_count <= entries
/// (which hitting every node needs), so it is bounded by bytes that were read.
void check_source_vertex_nodes(const Asset& a) {
  const std::vector<std::uint32_t>& map = a.source_vertex_nodes;
  if (map.empty()) return;
  if (a.body_kind != BodyKind::kSurface)
    fail("source_vertex_nodes has " + std::to_string(map.size()) +
         " entries but the body kind is not kSurface");
  if (a.node_count > map.size())
    fail("source_vertex_nodes has " + std::to_string(map.size()) + " entries, fewer than the " +
         std::to_string(a.node_count) + " nodes it must all reach");
  std::vector<bool> hit(a.node_count, false);
  for (std::size_t i = 0; i < map.size(); ++i) {
    if (map[i] >= a.node_count)
      fail(at("source_vertex_nodes", i) + " is " + std::to_string(map[i]) + " >= node_count " +
           std::to_string(a.node_count));
    hit[map[i]] = true;
  }
  const auto missed = std::find(hit.begin(), hit.end(), false);
  if (missed != hit.end())
    fail("node " + std::to_string(missed - hit.begin()) +
         " is no source vertex's node (source_vertex_nodes must reach every node)");
}

/// kTetPoint: node-form detectors are interior: not a vertex of any surface triangle. Searches
/// the (few) detector ids for every triangle corner rather than sorting all surface nodes.
void check_detectors(const Asset& a) {
  if (a.detector_form != DetectorForm::kTetPoint) return;
  std::vector<std::uint32_t> detectors;
  detectors.reserve(a.clusters.size());
  for (const Cluster& c : a.clusters)
    if (c.detector.is_node()) detectors.push_back(c.detector.nodes[0]);
  std::sort(detectors.begin(), detectors.end());
  detectors.erase(std::unique(detectors.begin(), detectors.end()), detectors.end());
  for (std::size_t t = 0; t < a.triangles.size(); ++t) {
    for (std::uint32_t v : a.triangles[t]) {
      if (std::binary_search(detectors.begin(), detectors.end(), v)) {
        for (std::size_t c = 0; c < a.clusters.size(); ++c) {
          if (a.clusters[c].detector.is_node() && a.clusters[c].detector.nodes[0] == v) {
            fail(at("clusters", c) + ".detector_node " + std::to_string(v) +
                 " is a surface node (of triangle " + std::to_string(t) + ")");
          }
        }
      }
    }
  }
}

void check_bvhs(const Asset& a) {
  std::vector<std::uint8_t> parents;
  std::vector<std::uint8_t> covered;
  for (std::size_t c = 0; c < a.clusters.size(); ++c) {
    const Cluster& cl = a.clusters[c];
    const BvhNode* nodes = a.bvh_nodes.data() + cl.bvh_offset;
    const std::uint32_t n = cl.bvh_count;
    parents.assign(n, 0);
    covered.assign(cl.triangle_count, 0);
    std::uint64_t leaves = 0;
    const std::string where = "cluster " + std::to_string(c) + " BVH node ";
    for (std::uint32_t i = 0; i < n; ++i) {
      const BvhNode& node = nodes[i];
      if (node.count > 0) {
        ++leaves;
        if (node.second != 0) fail(where + std::to_string(i) + ": leaf with non-zero second");
        if (std::uint64_t(node.first) + node.count > cl.triangle_count) {
          fail(where + std::to_string(i) + ": leaf range exceeds the cluster's " +
               std::to_string(cl.triangle_count) + " triangles");
        }
        for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
          if (covered[k])
            fail(where + std::to_string(i) + ": triangle position " + std::to_string(k) +
                 " is in two leaves");
          covered[k] = 1;
        }
      } else {
        for (std::uint32_t child : {node.first, node.second}) {
          if (child <= i || child >= n) {
            fail(where + std::to_string(i) + ": child " + std::to_string(child) + " is not in (" +
                 std::to_string(i) + ", " + std::to_string(n) + ")");
          }
          if (parents[child]) fail(where + std::to_string(child) + " has two parents");
          parents[child] = 1;
        }
      }
    }
    for (std::uint32_t i = 1; i < n; ++i) {
      if (!parents[i]) fail(where + std::to_string(i) + " has no parent");
    }
    for (std::uint32_t k = 0; k < cl.triangle_count; ++k) {
      if (!covered[k])
        fail("cluster " + std::to_string(c) + ": triangle position " + std::to_string(k) +
             " is in no leaf");
    }
    if (std::uint64_t(n) != 2 * leaves - 1) {
      fail("cluster " + std::to_string(c) + ": " + std::to_string(n) + " BVH nodes for " +
           std::to_string(leaves) + " leaves");
    }
  }
}

void check_boundaries(const Asset& a) {
  // Structure first, then one pass over the surface edges that marks the loop edges found.
  std::uint64_t next = 0;
  std::vector<std::uint64_t> loop_edges;
  loop_edges.reserve(a.boundary_nodes.size());
  for (std::size_t b = 0; b < a.boundaries.size(); ++b) {
    const BoundaryLoop& loop = a.boundaries[b];
    if (loop.node_count < 3) fail(at("boundaries", b) + " has fewer than 3 nodes");
    if (loop.node_offset != next) {
      fail(at("boundaries", b) + ".node_offset is " + std::to_string(loop.node_offset) +
           ", expected " + std::to_string(next) + " (loops are contiguous)");
    }
    next += loop.node_count;
    if (next > a.boundary_nodes.size()) fail(at("boundaries", b) + " exceeds boundary_nodes");
    const std::uint32_t* ids = a.boundary_nodes.data() + loop.node_offset;
    for (std::uint32_t i = 0; i < loop.node_count; ++i) {
      if (ids[i] >= a.node_count) {
        fail(at("boundaries", b) + " has node " + std::to_string(ids[i]) + " >= node_count " +
             std::to_string(a.node_count));
      }
    }
    for (std::uint32_t i = 0; i < loop.node_count; ++i) {
      const std::uint32_t u = ids[i];
      const std::uint32_t v = ids[(i + 1) % loop.node_count];
      if (u == v) {
        fail(at("boundaries", b) + ": nodes " + std::to_string(u) + " and " + std::to_string(v) +
             " are not a surface edge");
      }
      loop_edges.push_back(edge_key(u, v));
    }
  }
  if (next != a.boundary_nodes.size()) {
    fail("boundaries use " + std::to_string(next) + " of " +
         std::to_string(a.boundary_nodes.size()) + " boundary_nodes");
  }
  if (loop_edges.empty()) return;
  std::sort(loop_edges.begin(), loop_edges.end());
  loop_edges.erase(std::unique(loop_edges.begin(), loop_edges.end()), loop_edges.end());
  std::vector<std::uint8_t> found(loop_edges.size(), 0);
  auto mark = [&](std::uint32_t u, std::uint32_t v) {
    const auto it = std::lower_bound(loop_edges.begin(), loop_edges.end(), edge_key(u, v));
    if (it != loop_edges.end() && *it == edge_key(u, v)) found[it - loop_edges.begin()] = 1;
  };
  for (const Triangle& t : a.triangles) {
    mark(t[0], t[1]);
    mark(t[1], t[2]);
    mark(t[2], t[0]);
  }
  for (std::size_t e = 0; e < loop_edges.size(); ++e) {
    if (found[e]) continue;
    const auto u = static_cast<std::uint32_t>(loop_edges[e] >> 32);
    const auto v = static_cast<std::uint32_t>(loop_edges[e] & 0xFFFFFFFFu);
    // Name the first loop that uses the missing edge, as "nodes <u> and <v>" in loop order.
    for (std::size_t b = 0; b < a.boundaries.size(); ++b) {
      const BoundaryLoop& loop = a.boundaries[b];
      const std::uint32_t* ids = a.boundary_nodes.data() + loop.node_offset;
      for (std::uint32_t i = 0; i < loop.node_count; ++i) {
        const std::uint32_t x = ids[i];
        const std::uint32_t y = ids[(i + 1) % loop.node_count];
        if (edge_key(x, y) == loop_edges[e]) {
          fail(at("boundaries", b) + ": nodes " + std::to_string(x) + " and " + std::to_string(y) +
               " are not a surface edge");
        }
      }
    }
    fail("boundary edge " + std::to_string(u) + "-" + std::to_string(v) + " is not a surface edge");
  }
}

}  // namespace

Status validate(const Asset& asset, std::string* detail) noexcept {
  std::string why;
  try {
    check_limits(asset);
    check_nodes_and_triangles(asset);
    check_body_and_form(asset);
    check_partition(asset);
    check_detector_terms(asset);
    check_source_vertex_nodes(asset);
    check_detectors(asset);
    check_bvhs(asset);
    check_boundaries(asset);
    if (detail) detail->clear();
    return Status::kOk;
  } catch (Invalid& e) {
    why = std::move(e.message);
  } catch (const std::exception& e) {
    try {
      why = std::string("validation failed: ") + e.what();
    } catch (...) {
    }
  } catch (...) {
  }
  if (detail) {
    try {
      *detail = std::move(why);
    } catch (...) {
    }
  }
  return Status::kInvalidContent;
}

}  // namespace tetseg::format
