// rvbc with many clusters against the brute-force oracle, in the configurations that would trap
// culling across clusters (docs/runtime.md, "Across clusters by orientation: not adopted"):
// neighbouring clusters folded onto each other, wedge tips on a cluster boundary, detectors on both
// sides of a contact, and random smooth deformations of many small clusters; and the seam rule
// (pairs of two clusters sharing a node culled, their feature pairs tested from the seam orphans:
// "Across clusters: seam pairs") on low-valence bodies in every split into clusters and on
// scattered clusters. compare_with_oracle checks any-collision, the earliest toi, every oracle
// contact at the earliest toi, nothing outside the oracle's contacts and the exact contacts
// (tests/runtime/support/compare.hpp).

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "runtime/support/compare.hpp"
#include "runtime/support/motions.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"

using namespace tetseg;
using namespace tetseg::test;

namespace {

// A capsule of radius 0.35 along z from -2 to 2.
Surface capsule(int segments, int rings) {
  auto r = [](double z) {
    const double a = std::fabs(z);
    return a < 1.65 ? 0.35 : std::sqrt(std::max(0.0, 0.35 * 0.35 - (a - 1.65) * (a - 1.65)));
  };
  return revolve(sample_profile(r, -2.0, 2.0, rings), segments, 0.17);
}

// Clusters by sector of the centroid's angle about z (`sectors` equal sectors starting at
// `phase`) times axial slab (cuts in z); each cluster's detector is off the axis, inside the
// body, towards its sector's middle (radius `detector_r`) at the slab's middle height.
Scene sector_scene(const Surface& s, int sectors, double phase, const std::vector<double>& cuts,
                   const std::vector<double>& slab_z, double detector_r) {
  std::vector<std::uint32_t> cluster_of(s.tris.size());
  const std::uint32_t slabs = static_cast<std::uint32_t>(cuts.size() + 1);
  for (std::size_t t = 0; t < s.tris.size(); ++t) {
    P3 c = {0, 0, 0};
    for (std::uint32_t v : s.tris[t])
      for (int k = 0; k < 3; ++k) c[k] += s.verts[v][k] / 3;
    double a = std::atan2(c[1], c[0]) - phase;
    a -= 2 * M_PI * std::floor(a / (2 * M_PI));
    const std::uint32_t sector =
        std::min<std::uint32_t>(static_cast<std::uint32_t>(a / (2 * M_PI) * sectors),
                                static_cast<std::uint32_t>(sectors - 1));
    const std::uint32_t slab =
        static_cast<std::uint32_t>(std::upper_bound(cuts.begin(), cuts.end(), c[2]) - cuts.begin());
    cluster_of[t] = sector * slabs + slab;
  }
  std::vector<P3> detectors;
  for (int sector = 0; sector < sectors; ++sector) {
    const double a = phase + 2 * M_PI * (sector + 0.5) / sectors;
    for (std::uint32_t slab = 0; slab < slabs; ++slab)
      detectors.push_back({detector_r * std::cos(a), detector_r * std::sin(a), slab_z[slab]});
  }
  return make_scene(s, cluster_of, detectors);
}

// Folds everything above z = 0 about the x-parallel axis through (y, z) = (-0.25, 0), up to
// `angle` at t = 1, blended over |z| < 0.3: the capsule closes like a book and the sheets on
// both sides of the crease (and of a cut at z = 0) meet.
P3 fold_capsule(const P3& p, double t, double angle) {
  const double a = t * angle * smoothstep(p[2], -0.3, 0.3);
  const double y = p[1] + 0.25, z = p[2];
  return {p[0], -0.25 + y * std::cos(a) - z * std::sin(a), y * std::sin(a) + z * std::cos(a)};
}

}  // namespace

TEST_CASE("Neighbouring clusters folded onto each other agree with brute force",
          "[collider][rvbc][cross]") {
  const Surface s = capsule(16, 44);
  const auto cut_set = GENERATE(std::vector<double>{0.0}, std::vector<double>{-0.1, 0.1},
                                std::vector<double>{-0.35, 0.0, 0.2});
  const int sectors = GENERATE(1, 2, 3);
  CAPTURE(cut_set, sectors);
  std::vector<double> slab_z;
  for (std::size_t i = 0; i <= cut_set.size(); ++i) {
    const double lo = i == 0 ? -2.0 : cut_set[i - 1], hi = i == cut_set.size() ? 2.0 : cut_set[i];
    slab_z.push_back((lo + hi) / 2);
  }
  const Scene scene = sector_scene(s, sectors, 0.3, cut_set, slab_z, sectors == 1 ? 0.0 : 0.2);
  const auto frames =
      make_frames(scene, 24, [](const P3& p, double t) { return fold_capsule(p, t, 3.1); });
  const SequenceReport rep = compare_with_oracle(scene, frames);
  REQUIRE(rep.contact_frames == 1);
}

TEST_CASE("A wedge tip on a cluster boundary drooping onto another cluster agrees with brute force",
          "[collider][rvbc][cross][wedge]") {
  // The mushroom's rim (a wedge) droops onto its conical base; the sector boundary runs
  // through the rim vertex that touches first, and the cap and the stem are different slabs,
  // with detectors on opposite sides of the boundary (a configuration where culling a pair by
  // either cluster's detector alone could lose the first contact).
  const Surface s = mushroom(24);
  const double slant = GENERATE(-0.3, 0.05, 0.4);  // droop direction off the rim's plane
  const int sectors = GENERATE(2, 4);
  CAPTURE(slant, sectors);
  const RimDroop droop(s, slant);
  const Scene scene = sector_scene(s, sectors, droop.phi, {1.6}, {0.8, 2.1}, 0.45);
  const auto frames = make_frames(scene, 16, droop);
  const SequenceReport rep = compare_with_oracle(scene, frames);
  REQUIRE(rep.contact_frames == 1);
  REQUIRE_FALSE(rep.first_contacts.empty());
}

TEST_CASE("Many small clusters under random smooth deformations agree with brute force",
          "[collider][rvbc][cross]") {
  const unsigned seed = GENERATE(1u, 2u, 3u, 4u, 5u);
  const int shape = GENERATE(0, 1);
  CAPTURE(seed, shape);
  const Surface s = shape == 0 ? sphere(1.0, 20, 11) : dumbbell(16, 26);
  const Scene scene = shape == 0
                          ? sector_scene(s, 4, 0.1, {-0.4, 0.3}, {-0.7, 0.0, 0.6}, 0.3)
                          : sector_scene(s, 3, 0.2, {-1.0, 0.0, 1.0}, {-1.6, -0.5, 0.5, 1.6}, 0.15);
  const Waves waves(seed, 0.9, 4.0);
  const auto frames = make_frames(scene, 12, waves);
  const SequenceReport rep = compare_with_oracle(scene, frames);
  CHECK(rep.contact_frames == 1);  // the waves do reach a contact
}

TEST_CASE(
    "Detectors of two clusters seeing the contact edge-on from both sides agree with brute force",
    "[collider][rvbc][cross]") {
  // The trap of culling a pair of two clusters by a common detector of *either* cluster: the
  // poles of a sphere are pressed until they touch (a vertex on a face, or two edges). The two
  // detectors are put on a line through the contact point x in the touched sheet's tangent
  // plane, on both sides of x and a hair outside it: the touched triangles have one sign
  // against both, while the triangles around the touching vertex or edge split, some sharing
  // that sign against detector 0, the others against detector 1. Clusters: top and bottom, or
  // split by a plane at the contact (so that the triangles around it are near a boundary).
  const Surface s = sphere(1.0, 20, 11);
  std::vector<std::uint32_t> cluster_of(s.tris.size());
  for (std::size_t t = 0; t < s.tris.size(); ++t)
    cluster_of[t] =
        s.verts[s.tris[t][0]][2] + s.verts[s.tris[t][1]][2] + s.verts[s.tris[t][2]][2] > 0 ? 0 : 1;
  // Locate the first contact with provisional detectors.
  const Scene probe = make_scene(s, cluster_of, {{0, 0, 0.5}, {0, 0, -0.5}});
  const auto probe_frames = make_frames(probe, 16, press_poles);
  Contact first;
  bool found = false;
  std::size_t step = 0;
  for (; step + 1 < probe_frames.size() && !found; ++step) {
    const std::vector<Contact> oracle =
        oracle_contacts(probe, probe_frames[step].data(), probe_frames[step + 1].data());
    found = !oracle.empty();
    if (found) first = oracle.front();
  }
  REQUIRE(found);
  const auto& x0 = probe_frames[step - 1];
  const auto& x1 = probe_frames[step];
  auto at = [&](std::uint32_t node, double t) {
    P3 q;
    for (int k = 0; k < 3; ++k) q[k] = (1 - t) * x0[3 * node + k] + t * x1[3 * node + k];
    return q;
  };
  auto sub = [](const P3& u, const P3& v) { return P3{u[0] - v[0], u[1] - v[1], u[2] - v[2]}; };
  auto cross = [](const P3& u, const P3& v) {
    return P3{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  };
  auto unit = [](P3 u) {
    const double l = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double& v : u) v /= l;
    return u;
  };
  const double toi = first.toi;
  const auto& nd = first.nodes;
  // x: the contact point; n: the touched sheet's outward normal (towards the other sheet);
  // d: the detectors' line within that sheet's tangent plane.
  P3 x, n, d;
  const int variant = GENERATE(0, 1, 2, 3);
  const double eps = GENERATE(1e-4, 1e-2);
  CAPTURE(first.kind, variant, eps);
  if (first.kind == ContactKind::kVertexFace) {
    x = at(nd[0], toi);
    const P3 a = at(nd[1], toi), b = at(nd[2], toi), c = at(nd[3], toi);
    n = unit(cross(sub(b, a), sub(c, a)));  // outward: towards the vertex's sheet
    const P3 e1 = unit(sub(b, a)), e2 = cross(n, e1);
    const double angle = 0.8 * variant;
    for (int k = 0; k < 3; ++k) d[k] = std::cos(angle) * e1[k] + std::sin(angle) * e2[k];
  } else {
    const P3 a = at(nd[0], toi), b = at(nd[1], toi), c = at(nd[2], toi), e = at(nd[3], toi);
    for (int k = 0; k < 3; ++k) x[k] = (a[k] + b[k] + c[k] + e[k]) / 4;
    n = unit(cross(sub(b, a), sub(e, c)));
    const P3 m0 = sub(at(nd[0], 0), at(nd[2], 0));  // first edge relative to the second, t = 0
    if (n[0] * m0[0] + n[1] * m0[1] + n[2] * m0[2] < 0)
      for (double& v : n) v = -v;
    d = unit(variant % 2 ? sub(b, a) : sub(e, c));  // along one of the two edges
    if (variant >= 2) {                             // or halfway between them
      const P3 other = unit(variant % 2 ? sub(e, c) : sub(b, a));
      d = unit(P3{d[0] + other[0], d[1] + other[1], d[2] + other[2]});
    }
  }
  std::vector<P3> detectors(2);
  for (int k = 0; k < 3; ++k) {
    detectors[0][k] = x[k] - 2 * d[k] + eps * n[k];
    detectors[1][k] = x[k] + 2 * d[k] + eps * n[k];
  }
  // Clusters: top / bottom, or split by a plane through (near) x across or along the
  // detectors' line (triangle centroids at the contact time), so that the triangles around the
  // contact lie near a cluster boundary and are classified against both detectors.
  const int split = GENERATE(0, 1, 2);
  CAPTURE(split);
  std::vector<std::uint32_t> clusters = cluster_of;
  if (split > 0) {
    const P3 g = split == 1 ? d : unit(cross(d, n));
    for (std::size_t t = 0; t < s.tris.size(); ++t) {
      double side = -0.03;
      for (std::uint32_t v : s.tris[t]) {
        const P3 q = at(v, toi);
        for (int k = 0; k < 3; ++k) side += (q[k] - x[k]) * g[k] / 3;
      }
      clusters[t] = side > 0 ? 1 : 0;
    }
  }
  const Scene scene = make_scene(s, clusters, detectors);
  // The same surface motion; the detectors stay where they are.
  auto frames = make_frames(scene, 16, press_poles);
  for (auto& f : frames)
    for (std::uint32_t i = 0; i < 2; ++i)
      for (int k = 0; k < 3; ++k) f[3 * (scene.surface_nodes + i) + k] = detectors[i][k];
  const SequenceReport rep = compare_with_oracle(scene, frames);
  REQUIRE(rep.contact_frames == 1);
}

namespace {

// Every partition of `n` triangles into at least two clusters (restricted growth strings:
// cluster ids in order of first use).
std::vector<std::vector<std::uint32_t>> cluster_splits(std::uint32_t n) {
  std::vector<std::vector<std::uint32_t>> out;
  std::vector<std::uint32_t> c(n, 0);
  while (true) {
    const std::uint32_t blocks = *std::max_element(c.begin(), c.end()) + 1;
    if (blocks >= 2) out.push_back(c);
    // Next string: the last position that can grow does, the rest restart at 0.
    std::size_t i = n;
    while (i-- > 1) {
      const std::uint32_t prefix_max = *std::max_element(c.begin(), c.begin() + i);
      if (c[i] <= prefix_max) {
        ++c[i];
        std::fill(c.begin() + i + 1, c.end(), 0u);
        break;
      }
    }
    if (i == 0 || i > n) break;
  }
  return out;
}

// A small closed surface and single-step motions of it, each with a first contact.
struct SeamCase {
  Surface surface;
  std::vector<std::vector<P3>> ends;  // end positions of the vertices, one motion each
};

// A tetrahedron: every two of its triangles share a node, so in any split into clusters every
// triangle pair across clusters is culled and the feature pairs they hold are seam orphans.
SeamCase tetrahedron_case() {
  SeamCase c;
  c.surface.verts = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 1}};
  c.surface.tris = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  c.ends = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.25, 0.3, -1}},        // apex through the base
            {{0, 0, 0}, {1, 0, 0}, {0.1, 1, 0.2}, {0.9, 0.8, -0.6}}};  // edge 2-3 crosses 0-1
  return c;
}

// A triangular bipyramid: apexes of valence 3, equator vertices of valence 4; an apex pushed
// through a face of the other half meets it where every holding pair shares a node.
SeamCase bipyramid_case() {
  SeamCase c;
  Surface& s = c.surface;
  for (int i = 0; i < 3; ++i)
    s.verts.push_back({std::cos(2 * M_PI * i / 3), std::sin(2 * M_PI * i / 3), 0.0});
  s.verts.push_back({0.1, 0.05, 1.0});    // 3: top
  s.verts.push_back({-0.05, 0.1, -1.0});  // 4: bottom
  for (std::uint32_t i = 0; i < 3; ++i) {
    s.tris.push_back({i, (i + 1) % 3, 3});
    s.tris.push_back({(i + 1) % 3, i, 4});
  }
  orient_outward(s);
  auto moved = [&](std::uint32_t v, const P3& to) {
    std::vector<P3> e = s.verts;
    e[v] = to;
    return e;
  };
  c.ends = {moved(3, {0.35, 0.2, -0.9}),   // top through a bottom face
            moved(4, {-0.3, -0.25, 0.8}),  // bottom through a top face
            moved(3, {-0.9, 1.2, -0.4})};  // top swung across the equator: its edges cross
  return c;
}

}  // namespace

TEST_CASE("Feature pairs held only by triangle pairs of two clusters sharing a node are found",
          "[collider][rvbc][cross][seam]") {
  // rvbc culls every triangle pair of two clusters that shares a node and tests the feature
  // pairs that only such pairs hold across clusters from the seam-orphan list (docs/runtime.md,
  // "Across clusters: seam pairs"). On these low-valence bodies, in every split into clusters,
  // with detectors inside or far outside (more triangle pairs within a cluster culled by
  // orientation), and with every cluster overlap-only: any-collision, the earliest toi and
  // every contact at it agree with brute force, no contact is reported twice (answer()), and
  // with overlap-only clusters every contact of the step equals brute force's.
  const int body = GENERATE(0, 1);
  const SeamCase c = body == 0 ? tetrahedron_case() : bipyramid_case();
  const Surface& s = c.surface;
  const std::uint32_t nv = static_cast<std::uint32_t>(s.verts.size());
  int contact_steps = 0;
  for (const auto& split : cluster_splits(static_cast<std::uint32_t>(s.tris.size()))) {
    const std::uint32_t clusters = *std::max_element(split.begin(), split.end()) + 1;
    for (const P3 detector : {P3{0.3, 0.25, 0.2}, P3{4.0, -3.0, 2.5}}) {
      const Scene classified = make_scene(s, split, std::vector<P3>(clusters, detector));
      for (int overlap_only = 0; overlap_only < 2; ++overlap_only) {
        const Scene scene =
            overlap_only ? with_cluster_flags(classified, format::kClusterOverlapOnly) : classified;
        for (const auto& end : c.ends) {
          CAPTURE(body, split, detector, overlap_only, end);
          std::vector<double> x0 = scene.rest, x1 = scene.rest;
          for (std::uint32_t v = 0; v < nv; ++v)
            for (int k = 0; k < 3; ++k) x1[3 * v + k] = end[v][k];
          const SequenceReport rep = compare_with_oracle(scene, {x0, x1});
          REQUIRE(rep.contact_frames == 1);
          ++contact_steps;
          if (!overlap_only) continue;
          // Overlap-only clusters cull nothing by orientation: every oracle contact, at every
          // time, is found.
          Collider rvbc = collider_for(scene, ColliderMode::kRvbc);
          require_matches_oracle(answer(rvbc, x0.data(), x1.data()),
                                 step_truth(scene, x0.data(), x1.data()), Expect::kAllContacts);
        }
      }
    }
  }
  CHECK(contact_steps > 0);
}

TEST_CASE("Triangles scattered over many clusters under random deformations agree with brute force",
          "[collider][rvbc][cross][seam]") {
  // Every triangle in a random one of 5 clusters: almost every vertex lies on a seam, many
  // neighbouring pairs span two clusters (culled) and many feature pairs are seam orphans.
  const unsigned seed = GENERATE(1u, 2u, 3u, 4u);
  const int shape = GENERATE(0, 1);
  CAPTURE(seed, shape);
  const Surface s = shape == 0 ? sphere(1.0, 12, 7) : dumbbell(10, 16);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::uint32_t> pick(0, 4);
  std::vector<std::uint32_t> cluster_of(s.tris.size());
  for (auto& c : cluster_of) c = pick(rng);
  for (std::uint32_t c = 0; c < 5; ++c) cluster_of[c] = c;  // no cluster empty
  const Scene scene = make_scene(
      s, cluster_of,
      {{0.2, 0.1, 0.0}, {-0.2, 0.1, 0.1}, {0.0, -0.2, -0.1}, {0.1, 0.0, 0.3}, {0.0, 0.1, -0.3}});
  const Waves waves(seed, 1.0, 4.0);
  const auto frames = make_frames(scene, 12, waves);
  const SequenceReport rep = compare_with_oracle(scene, frames);
  CHECK(rep.contact_frames == 1);  // the waves do reach a contact
  // With OpenMP (the seam orphans tested after the parallel traversal) the answers and counts
  // are the serial ones, on the steps compared above.
  ColliderOptions parallel_options;
  parallel_options.use_openmp = true;
  Collider serial = collider_for(scene, ColliderMode::kRvbc);
  Collider parallel(scene.asset, parallel_options);
  for (int f = 0; f < rep.frames_compared; ++f) {
    CAPTURE(f);
    for (Collider* c : {&serial, &parallel})
      REQUIRE(c->step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    CHECK(any_ok(serial) == any_ok(parallel));
    // Counts after a stopped any-collision query depend on the threads: start the step again.
    for (Collider* c : {&serial, &parallel})
      REQUIRE(c->step(frames[f].data(), frames[f + 1].data()) == ColliderStatus::kOk);
    const EarliestContact es = earliest_ok(serial), ep = earliest_ok(parallel);
    REQUIRE(es.found == ep.found);
    if (es.found) CHECK(same_feature(es.contact, ep.contact));
    CHECK(contacts_ok(serial, nullptr, 0).found == contacts_ok(parallel, nullptr, 0).found);
    REQUIRE(parallel.stats().traversal_threads > 1);  // parallel against serial, not serial twice
    CHECK(serial.stats().feature_pairs == parallel.stats().feature_pairs);
    CHECK(serial.stats().feature_tests == parallel.stats().feature_tests);
    CHECK(serial.stats().triangle_pairs == parallel.stats().triangle_pairs);
  }
}
