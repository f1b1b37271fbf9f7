#include "soup_ccd.hpp"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <numeric>
#include <stdexcept>
#include <string>

#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/scene.hpp"

namespace tetseg::tools::soup {
namespace {

struct Box {
  std::array<double, 3> lo{INFINITY, INFINITY, INFINITY};
  std::array<double, 3> hi{-INFINITY, -INFINITY, -INFINITY};
  void add(const Box& b) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
    }
  }
  bool overlaps(const Box& b) const {  // closed boxes; exact comparisons
    for (int k = 0; k < 3; ++k)
      if (lo[k] > b.hi[k] || b.lo[k] > hi[k]) return false;
    return true;
  }
};

bool shares(const std::array<std::uint32_t, 3>& f, std::uint32_t v) {
  return f[0] == v || f[1] == v || f[2] == v;
}

/// Whether vertex v is still over the step (x0 == x1 bitwise: the runtime's rule).
bool still(const std::vector<std::array<double, 3>>& x0,
           const std::vector<std::array<double, 3>>& x1, std::uint32_t v) {
  return x0[v] == x1[v];
}

/// Swept box of every vertex over the step, enlarged by the minimum separation (rounded
/// outwards).
std::vector<Box> swept_vertex_boxes(const std::vector<std::array<double, 3>>& x0,
                                    const std::vector<std::array<double, 3>>& x1,
                                    const CcdOptions& options) {
  const double delta = options.min_separation > 0 ? options.min_separation : 0.0;
  std::vector<Box> boxes(x0.size());
  for (std::size_t v = 0; v < x0.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      boxes[v].lo[k] = std::min(x0[v][k], x1[v][k]);
      boxes[v].hi[k] = std::max(x0[v][k], x1[v][k]);
      if (delta > 0) {
        boxes[v].lo[k] = std::nextafter(boxes[v].lo[k] - delta, -INFINITY);
        boxes[v].hi[k] = std::nextafter(boxes[v].hi[k] + delta, INFINITY);
      }
    }
  }
  return boxes;
}

/// Sort and sweep along x over boxes of two kinds (`second_kind` true for the second): calls
/// visit(i, j) once for every pair of boxes of different kinds (or, when `same_kind`, every
/// pair) whose closed boxes overlap, i < j in the sorted order. One thread.
template <class Visit>
void sort_and_sweep(const std::vector<Box>& boxes, const std::vector<bool>& second_kind,
                    bool same_kind, Visit&& visit) {
  std::vector<std::uint32_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(),
            [&](std::uint32_t a, std::uint32_t b) { return boxes[a].lo[0] < boxes[b].lo[0]; });
  for (std::size_t i = 0; i < order.size(); ++i) {
    const Box& bi = boxes[order[i]];
    for (std::size_t j = i + 1; j < order.size() && boxes[order[j]].lo[0] <= bi.hi[0]; ++j) {
      const std::uint32_t a = order[i], b = order[j];
      if (!same_kind && second_kind[a] == second_kind[b]) continue;
      const Box& bj = boxes[b];
      if (bi.lo[1] > bj.hi[1] || bj.lo[1] > bi.hi[1] || bi.lo[2] > bj.hi[2] || bj.lo[2] > bi.hi[2])
        continue;
      visit(a, b);
    }
  }
}

// The sort-and-sweep pipeline of the scalable-CCD papers, as a baseline: swept boxes of every
// vertex, unique edge and face; one sweep along x over vertices and faces (vertex-face
// candidates), one over edges (edge-edge candidates); pairs sharing a vertex skipped; every
// candidate (listed, as those pipelines do) through the same pre-filter and elementary test
// as the runtime. Contacts in the order of `find_contacts`.
std::vector<Contact> sweep_contacts(const std::vector<std::array<double, 3>>& x0,
                                    const std::vector<std::array<double, 3>>& x1,
                                    const std::vector<std::array<std::uint32_t, 3>>& faces,
                                    const CcdOptions& options, FrameStats* stats,
                                    StillPairs still_pairs) {
  const bool skip_still = still_pairs == StillPairs::kSkip;
  FrameStats local;
  FrameStats& st = stats ? *stats : local;
  const double start = thread_cpu_seconds();
  const std::vector<Box> vertex_boxes = swept_vertex_boxes(x0, x1, options);
  std::vector<std::uint32_t> used(x0.size(), 0);  // vertices referenced by a face
  for (const auto& f : faces)
    for (auto v : f) used[v] = 1;
  std::vector<std::array<std::uint32_t, 2>> edges;  // a < b, unique
  edges.reserve(faces.size() * 3);
  for (const auto& f : faces)
    for (int i = 0; i < 3; ++i)
      edges.push_back({std::min(f[i], f[(i + 1) % 3]), std::max(f[i], f[(i + 1) % 3])});
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  // Vertex-face: boxes of the used vertices, then of the faces.
  std::vector<Box> boxes;
  std::vector<std::uint32_t> ids;
  std::vector<bool> is_face;
  for (std::uint32_t v = 0; v < x0.size(); ++v) {
    if (!used[v]) continue;
    boxes.push_back(vertex_boxes[v]);
    ids.push_back(v);
    is_face.push_back(false);
  }
  for (std::uint32_t f = 0; f < faces.size(); ++f) {
    Box box;
    for (auto v : faces[f]) box.add(vertex_boxes[v]);
    boxes.push_back(box);
    ids.push_back(f);
    is_face.push_back(true);
  }
  std::vector<std::array<std::uint32_t, 2>> vf;  // vertex, face
  sort_and_sweep(boxes, is_face, false, [&](std::uint32_t a, std::uint32_t b) {
    if (is_face[a]) std::swap(a, b);
    if (!shares(faces[ids[b]], ids[a])) vf.push_back({ids[a], ids[b]});
  });
  boxes.clear();
  for (const auto& e : edges) {
    Box box = vertex_boxes[e[0]];
    box.add(vertex_boxes[e[1]]);
    boxes.push_back(box);
  }
  std::vector<std::array<std::uint32_t, 2>> ee;  // edge indices
  sort_and_sweep(boxes, {}, true, [&](std::uint32_t i, std::uint32_t j) {
    const auto &e = edges[i], &g = edges[j];
    if (e[0] != g[0] && e[0] != g[1] && e[1] != g[0] && e[1] != g[1]) ee.push_back({i, j});
  });
  st.vf_candidates = vf.size();
  st.ee_candidates = ee.size();
  const double tests_start = thread_cpu_seconds();

  struct Found {
    Contact contact;
    std::uint32_t face;  // vertex-face: face index (for the order)
  };
  std::vector<Found> found;
  for (const auto& [v, f] : vf) {
    const auto& face = faces[f];
    const Vec3d &p0 = x0[v], &a0 = x0[face[0]], &b0 = x0[face[1]], &c0 = x0[face[2]];
    const Vec3d &p1 = x1[v], &a1 = x1[face[0]], &b1 = x1[face[1]], &c1 = x1[face[2]];
    if (skip_still && still(x0, x1, v) && still(x0, x1, face[0]) && still(x0, x1, face[1]) &&
        still(x0, x1, face[2]))
      continue;
    if (!vertex_face_ccd_filter(p0, a0, b0, c0, p1, a1, b1, c1, options)) continue;
    ++st.tests;
    const CcdResult r = vertex_face_ccd(p0, a0, b0, c0, p1, a1, b1, c1, options);
    if (r.hit()) found.push_back({{true, {v, face[0], face[1], face[2]}, r.toi}, f});
  }
  for (const auto& [i, j] : ee) {
    auto e = edges[i], g = edges[j];
    if (g < e) std::swap(e, g);
    const Vec3d &a0 = x0[e[0]], &b0 = x0[e[1]], &c0 = x0[g[0]], &d0 = x0[g[1]];
    const Vec3d &a1 = x1[e[0]], &b1 = x1[e[1]], &c1 = x1[g[0]], &d1 = x1[g[1]];
    if (skip_still && still(x0, x1, e[0]) && still(x0, x1, e[1]) && still(x0, x1, g[0]) &&
        still(x0, x1, g[1]))
      continue;
    if (!edge_edge_ccd_filter(a0, b0, c0, d0, a1, b1, c1, d1, options)) continue;
    ++st.tests;
    const CcdResult r = edge_edge_ccd(a0, b0, c0, d0, a1, b1, c1, d1, options);
    if (r.hit()) found.push_back({{false, {e[0], e[1], g[0], g[1]}, r.toi}, 0});
  }
  const double tests_end = thread_cpu_seconds();
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    if (a.contact.vertex_face != b.contact.vertex_face) return a.contact.vertex_face;
    if (a.contact.vertex_face && a.contact.ids[0] != b.contact.ids[0])
      return a.contact.ids[0] < b.contact.ids[0];
    if (a.contact.vertex_face) return a.face < b.face;
    return a.contact.ids < b.contact.ids;
  });
  std::vector<Contact> contacts;
  contacts.reserve(found.size());
  for (const Found& f : found) contacts.push_back(f.contact);
  st.broad_seconds = tests_start - start;
  st.test_seconds = tests_end - tests_start;
  return contacts;
}

// Room for the runtime's contacts: dense contact frames such as cloth-ball have about 1.2 per
// face; more take a second traversal. A larger buffer costs its first touch (about 6 ms per
// 15 MB on the benchmark VM), every frame.
constexpr std::size_t kContactsPerFace = 2;

// Every contact of the step `query` (a Scene or a Collider, stepped) of a soup of `faces`
// faces: into a buffer of kContactsPerFace per face, once more into one of the count found
// when that was too small.
template <class Query>
std::vector<tetseg::Contact> step_contacts(Query& query, std::size_t faces) {
  std::vector<tetseg::Contact> found(kContactsPerFace * faces + 1024);
  ContactsResult r;
  ColliderStatus st = query.contacts(found.data(), found.size(), r);
  if (st == ColliderStatus::kOk && r.truncated()) {
    found.resize(r.found);
    st = query.contacts(found.data(), found.size(), r);
  }
  if (st != ColliderStatus::kOk)
    throw std::runtime_error(std::string("query failed: ") + tetseg::to_string(st));
  found.resize(r.written);
  return found;
}

// The runtime's contacts in the order of `find_contacts`: vertex-face by (vertex, face id), then
// edge-edge by nodes.
std::vector<Contact> sorted_contacts(std::vector<tetseg::Contact>& found) {
  std::sort(found.begin(), found.end(), [](const tetseg::Contact& a, const tetseg::Contact& b) {
    if (a.kind != b.kind) return a.kind == ContactKind::kVertexFace;
    if (a.kind == ContactKind::kVertexFace && a.nodes[0] != b.nodes[0])
      return a.nodes[0] < b.nodes[0];
    if (a.kind == ContactKind::kVertexFace) return a.triangle < b.triangle;
    return a.nodes < b.nodes;
  });
  std::vector<Contact> contacts;
  contacts.reserve(found.size());
  for (const tetseg::Contact& c : found)
    contacts.push_back({c.kind == ContactKind::kVertexFace, c.nodes, c.toi});
  return contacts;
}

// The soup's faces over `nodes` vertices as a surface-only body; throws on a face with a
// repeated or out-of-range vertex.
std::shared_ptr<const BodyShape> soup_shape(const std::vector<std::array<std::uint32_t, 3>>& faces,
                                            std::uint32_t nodes) {
  std::vector<std::uint32_t> ids;
  ids.reserve(faces.size() * 3);
  for (const auto& f : faces) ids.insert(ids.end(), f.begin(), f.end());
  std::shared_ptr<const BodyShape> shape =
      BodyShape::from_triangles(ids.data(), faces.size(), nodes);
  if (!shape) throw std::runtime_error("faces with a repeated or out-of-range vertex");
  return shape;
}

// The soup as one surface-only body of a runtime scene (one median-split BVH over the swept
// triangle boxes, self traversal, exact deduplication, the runtime's feature filters and
// elementary tests). Memory: the mesh, the scene's scratch and the contacts found.
std::vector<Contact> scene_contacts(const std::vector<std::array<double, 3>>& x0,
                                    const std::vector<std::array<double, 3>>& x1,
                                    const std::vector<std::array<std::uint32_t, 3>>& faces,
                                    const CcdOptions& options, FrameStats* stats,
                                    StillPairs still_pairs, const tetseg::Asset* asset) {
  const auto nodes = static_cast<std::uint32_t>(x0.size());
  std::shared_ptr<const BodyShape> shape;
  if (asset != nullptr) {
    shape = BodyShape::from_asset(*asset);
    if (!shape) throw std::runtime_error("cannot set up the asset's body (out of memory)");
  } else {
    shape = soup_shape(faces, nodes);
  }
  std::vector<double> p0, p1;
  p0.reserve(x0.size() * 3);
  p1.reserve(x1.size() * 3);
  for (const auto& p : x0) p0.insert(p0.end(), p.begin(), p.end());
  for (const auto& p : x1) p1.insert(p1.end(), p.begin(), p.end());
  SceneOptions scene_options;
  scene_options.ccd = options;
  scene_options.time_tests = false;
  scene_options.include_still_pairs = still_pairs == StillPairs::kInclude;
  Scene scene(scene_options);
  std::uint32_t body = 0;
  if (scene.add_body(shape, BodyOptions{}, &body) != ColliderStatus::kOk ||
      scene.set_positions(body, p0.data(), p1.data(), p0.size()) != ColliderStatus::kOk)
    throw std::runtime_error("cannot set up the scene (out of memory)");
  // Bone-carried detectors: the frames carry no pose, so they stay at rest.
  std::vector<double> rest_detectors;
  if (asset != nullptr && asset->data().detector_form == tetseg::format::DetectorForm::kBones) {
    rest_detectors = tetseg::format::rest_detector_positions(asset->data());
    if (scene.set_detector_positions(body, rest_detectors.data(), rest_detectors.data(),
                                     rest_detectors.size()) != ColliderStatus::kOk)
      throw std::runtime_error("cannot set the detector positions");
  }
  const ColliderStatus st = scene.step();
  if (st != ColliderStatus::kOk)
    throw std::runtime_error(std::string("step rejected: ") + tetseg::to_string(st));
  std::vector<tetseg::Contact> found = step_contacts(scene, faces.size());
  if (stats != nullptr) {
    const ColliderStats& body_stats = scene.body_stats(body);
    stats->triangle_pairs = body_stats.triangle_pairs;
    stats->feature_pairs = body_stats.feature_pairs;
    stats->tests = body_stats.feature_tests;
    stats->orientation_culled = body_stats.node_pairs_orientation_culled;
  }
  return sorted_contacts(found);
}

// The soup as one Collider in ColliderMode::kFeatures (per-feature BVHs, the runtime's filters
// and elementary tests); contacts in the order of `find_contacts`.
std::vector<Contact> collider_features_contacts(
    const std::vector<std::array<double, 3>>& x0, const std::vector<std::array<double, 3>>& x1,
    const std::vector<std::array<std::uint32_t, 3>>& faces, const CcdOptions& options,
    FrameStats* stats, StillPairs still_pairs, std::uint32_t threads) {
  const auto nodes = static_cast<std::uint32_t>(x0.size());
  const std::shared_ptr<const BodyShape> shape = soup_shape(faces, nodes);
  ColliderOptions collider_options;
  collider_options.mode = ColliderMode::kFeatures;
  collider_options.ccd = options;
  collider_options.include_still_pairs = still_pairs == StillPairs::kInclude;
  collider_options.use_openmp = threads > 1;
  collider_options.threads = threads;
  Collider collider(shape, collider_options);
  const ColliderStatus st = collider.step(x0.front().data(), x1.front().data());
  if (st != ColliderStatus::kOk)
    throw std::runtime_error(std::string("step rejected: ") + tetseg::to_string(st));
  std::vector<tetseg::Contact> found = step_contacts(collider, faces.size());
  if (stats != nullptr) {
    const ColliderStats& s = collider.stats();
    stats->feature_pairs = s.feature_pairs;
    stats->tests = s.feature_tests;
  }
  return sorted_contacts(found);
}

}  // namespace

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

std::vector<Contact> find_contacts(const std::vector<std::array<double, 3>>& x0,
                                   const std::vector<std::array<double, 3>>& x1,
                                   const std::vector<std::array<std::uint32_t, 3>>& faces,
                                   const CcdOptions& options, BroadPhase broad_phase,
                                   FrameStats* stats, StillPairs still_pairs,
                                   const tetseg::Asset* asset, std::uint32_t threads) {
  if (broad_phase == BroadPhase::kFeatures && asset == nullptr) {
    if (x0.empty()) return {};
    return collider_features_contacts(x0, x1, faces, options, stats, still_pairs, threads);
  }
  if (broad_phase == BroadPhase::kScene || broad_phase == BroadPhase::kFeatures)
    return scene_contacts(x0, x1, faces, options, stats, still_pairs, asset);
  if (broad_phase == BroadPhase::kSweep)
    return sweep_contacts(x0, x1, faces, options, stats, still_pairs);
  const bool skip_still = still_pairs == StillPairs::kSkip;
  auto all_still = [&](const std::array<std::uint32_t, 4>& ids) {
    return skip_still && still(x0, x1, ids[0]) && still(x0, x1, ids[1]) && still(x0, x1, ids[2]) &&
           still(x0, x1, ids[3]);
  };
  const std::vector<Box> vertex_boxes = swept_vertex_boxes(x0, x1, options);
  std::vector<Box> face_boxes(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (auto v : faces[f]) face_boxes[f].add(vertex_boxes[v]);

  std::vector<std::array<std::uint32_t, 2>> vf_pairs;  // vertex, face
  std::vector<std::array<std::uint32_t, 4>> ee_pairs;  // a < b, c < d, (a,b) < (c,d)
  auto edge_box = [&](std::uint32_t a, std::uint32_t b) {
    Box box = vertex_boxes[a];
    box.add(vertex_boxes[b]);
    return box;
  };
  auto face_pair = [&](std::uint32_t f, std::uint32_t g) {
    const auto& ff = faces[f];
    const auto& gg = faces[g];
    for (auto v : ff)
      if (!shares(gg, v) && vertex_boxes[v].overlaps(face_boxes[g])) vf_pairs.push_back({v, g});
    for (auto v : gg)
      if (!shares(ff, v) && vertex_boxes[v].overlaps(face_boxes[f])) vf_pairs.push_back({v, f});
    for (int i = 0; i < 3; ++i) {
      std::uint32_t a = ff[i], b = ff[(i + 1) % 3];
      if (a > b) std::swap(a, b);
      const Box ea = edge_box(a, b);
      for (int j = 0; j < 3; ++j) {
        std::uint32_t c = gg[j], d = gg[(j + 1) % 3];
        if (c > d) std::swap(c, d);
        if (a == c || a == d || b == c || b == d) continue;
        if (!ea.overlaps(edge_box(c, d))) continue;
        if (std::make_pair(a, b) < std::make_pair(c, d))
          ee_pairs.push_back({a, b, c, d});
        else
          ee_pairs.push_back({c, d, a, b});
      }
    }
  };
  for (std::uint32_t f = 0; f < faces.size(); ++f)
    for (std::uint32_t g = f + 1; g < faces.size(); ++g)
      if (face_boxes[f].overlaps(face_boxes[g])) face_pair(f, g);
  std::sort(vf_pairs.begin(), vf_pairs.end());
  vf_pairs.erase(std::unique(vf_pairs.begin(), vf_pairs.end()), vf_pairs.end());
  std::sort(ee_pairs.begin(), ee_pairs.end());
  ee_pairs.erase(std::unique(ee_pairs.begin(), ee_pairs.end()), ee_pairs.end());

  std::vector<Contact> contacts;
  for (const auto& [v, f] : vf_pairs) {
    const auto& face = faces[f];
    if (all_still({v, face[0], face[1], face[2]})) continue;
    const CcdResult r = vertex_face_ccd(x0[v], x0[face[0]], x0[face[1]], x0[face[2]], x1[v],
                                        x1[face[0]], x1[face[1]], x1[face[2]], options);
    if (r.hit()) contacts.push_back({true, {v, face[0], face[1], face[2]}, r.toi});
  }
  for (const auto& e : ee_pairs) {
    if (all_still(e)) continue;
    const CcdResult r = edge_edge_ccd(x0[e[0]], x0[e[1]], x0[e[2]], x0[e[3]], x1[e[0]], x1[e[1]],
                                      x1[e[2]], x1[e[3]], options);
    if (r.hit()) contacts.push_back({false, e, r.toi});
  }
  return contacts;
}

}  // namespace tetseg::tools::soup
