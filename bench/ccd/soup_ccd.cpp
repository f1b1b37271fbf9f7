#include "soup_ccd.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

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

// The soup as one surface-only body of a runtime scene (one median-split BVH over the swept
// triangle boxes, self traversal, exact deduplication, the runtime's feature filters and
// elementary tests). Memory: the mesh, the scene's scratch and the contacts found.
std::vector<Contact> scene_contacts(const std::vector<std::array<double, 3>>& x0,
                                    const std::vector<std::array<double, 3>>& x1,
                                    const std::vector<std::array<std::uint32_t, 3>>& faces,
                                    const CcdOptions& options) {
  const auto nodes = static_cast<std::uint32_t>(x0.size());
  std::vector<std::uint32_t> ids;
  ids.reserve(faces.size() * 3);
  for (const auto& f : faces) ids.insert(ids.end(), f.begin(), f.end());
  auto shape = BodyShape::from_triangles(ids.data(), faces.size(), nodes);
  if (!shape) throw std::runtime_error("faces with a repeated or out-of-range vertex");
  std::vector<double> p0, p1;
  p0.reserve(x0.size() * 3);
  p1.reserve(x1.size() * 3);
  for (const auto& p : x0) p0.insert(p0.end(), p.begin(), p.end());
  for (const auto& p : x1) p1.insert(p1.end(), p.begin(), p.end());
  SceneOptions scene_options;
  scene_options.ccd = options;
  scene_options.time_tests = false;
  Scene scene(scene_options);
  std::uint32_t body = 0;
  if (scene.add_body(shape, BodyOptions{}, &body) != ColliderStatus::kOk ||
      scene.set_positions(body, p0.data(), p1.data(), p0.size()) != ColliderStatus::kOk)
    throw std::runtime_error("cannot set up the scene (out of memory)");
  ColliderStatus st = scene.step();
  if (st != ColliderStatus::kOk)
    throw std::runtime_error(std::string("step rejected: ") + tetseg::to_string(st));
  // Room for a few contacts per face (dense contact frames such as cloth-ball have about 1.2);
  // more take a second traversal.
  std::vector<tetseg::Contact> found(4 * faces.size() + 1024);
  ContactsResult r;
  st = scene.contacts(found.data(), found.size(), r);
  if (st == ColliderStatus::kOk && r.truncated()) {
    found.resize(r.found);
    st = scene.contacts(found.data(), found.size(), r);
  }
  if (st != ColliderStatus::kOk)
    throw std::runtime_error(std::string("query failed: ") + tetseg::to_string(st));
  found.resize(r.written);
  // Vertex-face by (vertex, face id), then edge-edge by nodes.
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

}  // namespace

std::vector<Contact> find_contacts(const std::vector<std::array<double, 3>>& x0,
                                   const std::vector<std::array<double, 3>>& x1,
                                   const std::vector<std::array<std::uint32_t, 3>>& faces,
                                   const CcdOptions& options, bool brute) {
  if (!brute) return scene_contacts(x0, x1, faces, options);
  const double delta = options.min_separation > 0 ? options.min_separation : 0.0;
  // Swept vertex boxes, enlarged by the minimum separation (rounded outwards).
  std::vector<Box> vertex_boxes(x0.size());
  for (std::size_t v = 0; v < x0.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      vertex_boxes[v].lo[k] = std::min(x0[v][k], x1[v][k]);
      vertex_boxes[v].hi[k] = std::max(x0[v][k], x1[v][k]);
      if (delta > 0) {
        vertex_boxes[v].lo[k] = std::nextafter(vertex_boxes[v].lo[k] - delta, -INFINITY);
        vertex_boxes[v].hi[k] = std::nextafter(vertex_boxes[v].hi[k] + delta, INFINITY);
      }
    }
  }
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
    const CcdResult r = vertex_face_ccd(x0[v], x0[face[0]], x0[face[1]], x0[face[2]], x1[v],
                                        x1[face[0]], x1[face[1]], x1[face[2]], options);
    if (r.hit()) contacts.push_back({true, {v, face[0], face[1], face[2]}, r.toi});
  }
  for (const auto& e : ee_pairs) {
    const CcdResult r = edge_edge_ccd(x0[e[0]], x0[e[1]], x0[e[2]], x0[e[3]], x1[e[0]], x1[e[1]],
                                      x1[e[2]], x1[e[3]], options);
    if (r.hit()) contacts.push_back({false, e, r.toi});
  }
  return contacts;
}

}  // namespace tetseg::tools::soup
