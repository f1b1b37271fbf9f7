// Surface bodies (build_surface_asset, `tetseg build --body surface`): the input surface kept
// exactly, detectors as valid weights of surface vertices, open components overlap-only,
// refusals with their reasons.

#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "tetseg/format/asset.hpp"
#include "tetseg/format/asset_io.hpp"
#include "tetseg/format/source_vertices.hpp"
#include "tetseg/preprocess/jobs.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/testing/charge_shapes.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tetseg/testing/skinned_tube.hpp"
#include "tetseg/testing/test_data.hpp"

using namespace tetseg::preprocess;
namespace format = tetseg::format;

namespace {

format::Asset surface_asset(const TriangleMesh& mesh, const BuildOptions& options = {}) {
  BuildOptions o = options;
  o.body = format::BodyKind::kSurface;
  BuildReport report;
  return build_surface_asset(mesh, "test.off", o, report);
}

/// Generalised winding number of `mesh` at `p` (sum of solid angles / 4 pi, Van Oosterom and
/// Strackee): about 1 inside a closed outward surface, 0 outside.
double winding_number(const TriangleMesh& mesh, const Vec3& p) {
  double total = 0.0;
  for (const Tri& t : mesh.triangles) {
    Vec3 a, b, c;
    for (int k = 0; k < 3; ++k) {
      a[k] = mesh.vertices[t[0]][k] - p[k];
      b[k] = mesh.vertices[t[1]][k] - p[k];
      c[k] = mesh.vertices[t[2]][k] - p[k];
    }
    auto len = [](const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); };
    auto dot = [](const Vec3& u, const Vec3& v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
    const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                       a[2] * (b[0] * c[1] - b[1] * c[0]);
    const double la = len(a), lb = len(b), lc = len(c);
    total += 2.0 * std::atan2(det, la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(a, c) * lb);
  }
  return total / (4.0 * M_PI);
}

/// Every check a surface asset's clusters and detectors pass against `mesh` (independent of
/// the build): the input kept exactly, every triangle in one cluster, detector terms valid,
/// detector_rest their combination (the runtime's evaluation order) and inside the body,
/// rest fractions counted again. Returns the number of clusters with a detector. `solid`
/// (default: `mesh`) is the surface the detectors must be inside of.
std::size_t check_surface_asset(const TriangleMesh& mesh, const format::Asset& asset,
                                const TriangleMesh* solid = nullptr) {
  REQUIRE(asset.body_kind == format::BodyKind::kSurface);
  REQUIRE(asset.detector_form == format::DetectorForm::kSurfaceWeights);
  REQUIRE(asset.node_count == mesh.vertices.size());
  REQUIRE(asset.rest_positions == mesh.vertices);  // bit for bit, in order
  REQUIRE(asset.triangles == mesh.triangles);      // in order, winding kept
  REQUIRE(asset.triangle_cluster.size() == mesh.triangles.size());
  std::vector<int> seen(mesh.triangles.size(), 0);
  std::size_t with_detector = 0;
  std::uint32_t next_term = 0;
  for (std::uint32_t c = 0; c < asset.clusters.size(); ++c) {
    const format::Cluster& cluster = asset.clusters[c];
    for (std::uint32_t i = 0; i < cluster.triangle_count; ++i) {
      const std::uint32_t t = asset.cluster_triangles[cluster.triangle_offset + i];
      REQUIRE(asset.triangle_cluster[t] == c);
      ++seen[t];
    }
    REQUIRE(cluster.detector_term_offset == next_term);
    next_term += cluster.detector_term_count;
    const bool overlap_only = (cluster.flags & format::kClusterOverlapOnly) != 0;
    if (overlap_only) {
      REQUIRE(cluster.detector_term_count == 0);
      continue;
    }
    ++with_detector;
    REQUIRE(cluster.detector_term_count >= 1);
    REQUIRE(cluster.detector_term_count <= kSurfaceDetectorTerms);
    REQUIRE(kSurfaceDetectorTerms <= format::kMaxDetectorTerms);
    std::set<std::uint32_t> indices;
    double sum = 0.0;
    std::array<double, 3> combination{0.0, 0.0, 0.0};
    for (std::uint32_t i = 0; i < cluster.detector_term_count; ++i) {
      const format::DetectorTerm& term = asset.detector_terms[cluster.detector_term_offset + i];
      REQUIRE(term.index < asset.node_count);
      REQUIRE(std::isfinite(term.weight));
      REQUIRE(term.weight > 0.0);
      indices.insert(term.index);
      sum += term.weight;
      for (int k = 0; k < 3; ++k) combination[k] += term.weight * mesh.vertices[term.index][k];
    }
    REQUIRE(indices.size() == cluster.detector_term_count);
    REQUIRE(std::fabs(sum - 1.0) <= format::kDetectorWeightSumTolerance);
    REQUIRE(combination == cluster.detector_rest);
    REQUIRE(winding_number(solid ? *solid : mesh, cluster.detector_rest) > 0.5);
    // The rest fraction, counted again from detector_rest.
    std::uint32_t positive = 0;
    for (std::uint32_t i = 0; i < cluster.triangle_count; ++i) {
      const Tri& t = mesh.triangles[asset.cluster_triangles[cluster.triangle_offset + i]];
      const Vec3& o = cluster.detector_rest;
      double a[3], b[3], e[3];
      for (int k = 0; k < 3; ++k) {
        a[k] = mesh.vertices[t[0]][k] - o[k];
        b[k] = mesh.vertices[t[1]][k] - o[k];
        e[k] = mesh.vertices[t[2]][k] - o[k];
      }
      const double det = a[0] * (b[1] * e[2] - b[2] * e[1]) - a[1] * (b[0] * e[2] - b[2] * e[0]) +
                         a[2] * (b[0] * e[1] - b[1] * e[0]);
      positive += det > 0.0 ? 1 : 0;
    }
    REQUIRE(cluster.rest_positive_fraction ==
            static_cast<float>(double(positive) / double(cluster.triangle_count)));
  }
  REQUIRE(next_term == asset.detector_terms.size());
  for (int count : seen) REQUIRE(count == 1);
  return with_detector;
}

/// `mesh` with its vertices renumbered by `(v * stride) mod n` and its triangles reversed in
/// order and rotated: the same surface in another order.
TriangleMesh reordered(const TriangleMesh& mesh, std::uint32_t stride) {
  const std::uint32_t n = static_cast<std::uint32_t>(mesh.vertices.size());
  TriangleMesh out;
  out.vertices.resize(n);
  std::vector<std::uint32_t> to(n);
  for (std::uint32_t v = 0; v < n; ++v) {
    to[v] = static_cast<std::uint32_t>((std::uint64_t(v) * stride) % n);
    out.vertices[to[v]] = mesh.vertices[v];
  }
  for (std::size_t i = mesh.triangles.size(); i-- > 0;) {
    const Tri& t = mesh.triangles[i];
    out.triangles.push_back({to[t[1]], to[t[2]], to[t[0]]});
  }
  return out;
}

TriangleMesh translated(TriangleMesh mesh, double dx) {
  for (Vec3& v : mesh.vertices) v[0] += dx;
  return mesh;
}

/// `a` and `b` as one surface (b's vertex ids after a's).
TriangleMesh joined(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh out = a;
  const auto offset = static_cast<std::uint32_t>(a.vertices.size());
  out.vertices.insert(out.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const Tri& t : b.triangles)
    out.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return out;
}

std::string refusal(const TriangleMesh& mesh) {
  try {
    surface_asset(mesh);
  } catch (const InputError& e) {
    REQUIRE(e.file() == "test.off");
    return e.what();
  }
  FAIL("the surface was accepted");
  return {};
}

}  // namespace

TEST_CASE("A surface body keeps the input's vertices and triangles in their order",
          "[surface-body]") {
  const TriangleMesh pawn = tetseg::test::pawn(0.05);
  const format::Asset asset = surface_asset(pawn);
  CHECK(asset.clusters.size() > 1);
  CHECK(check_surface_asset(pawn, asset) == asset.clusters.size());
  // The same surface in another order gives an asset in that order.
  const TriangleMesh shuffled = reordered(pawn, 7919);
  REQUIRE(shuffled.vertices != pawn.vertices);
  check_surface_asset(shuffled, surface_asset(shuffled));
  // A surface with vertices no triangle uses keeps them too (the runtime receives them).
  TriangleMesh extra = tetseg::test::icosphere(4);
  extra.vertices.insert(extra.vertices.begin() + 3, Vec3{5.0, 5.0, 5.0});
  for (Tri& t : extra.triangles)
    for (std::uint32_t& v : t) v += v >= 3 ? 1 : 0;
  check_surface_asset(extra, surface_asset(extra));
}

TEST_CASE("A libcgal-demo surface body keeps its mesh exactly, detectors inside",
          "[surface-body][cgal]") {
  for (const char* name : {"elephant", "blobby_3cc"}) {
    const std::string path = std::string(TETSEG_CGAL_MESH_DIR) + "/" + name + ".off";
    if (!tetseg::test::have_test_data(path, "libcgal-demo mesh")) return;
    const TriangleMesh mesh = tetseg::test::read_off(path);
    BuildJobOptions options;
    options.build.body = format::BodyKind::kSurface;
    const BuildJobResult result = build_asset_from_file(path, options);
    INFO(name);
    const std::size_t with_detector = check_surface_asset(mesh, result.asset);
    if (std::string(name) == "elephant") {
      CHECK(with_detector == result.asset.clusters.size());
      CHECK(result.asset.clusters.size() > 3);
    } else {  // three open components: one overlap-only cluster each
      CHECK(with_detector == 0);
      CHECK(result.asset.clusters.size() == 3);
    }
    const std::string report = build_report_json(result, path, "");
    CHECK(report.find("\"body\": \"surface\", \"detectors\": \"weights\"") != std::string::npos);
    const auto& recorded = result.asset.provenance.options;
    CHECK(std::count(recorded.begin(), recorded.end(),
                     std::make_pair(std::string("body"), std::string("surface"))) == 1);
    CHECK(std::count(recorded.begin(), recorded.end(),
                     std::make_pair(std::string("detectors"), std::string("weights"))) == 1);
    BuildOptions back;
    REQUIRE(options_from_provenance(recorded, back));
    CHECK(back.body == format::BodyKind::kSurface);
    CHECK(detector_form_of(back) == format::DetectorForm::kSurfaceWeights);
  }
}

TEST_CASE("An open component gets overlap-only clusters, closed ones get detectors",
          "[surface-body]") {
  // A sphere and, beside it, a sphere with a cap cut off (open).
  const TriangleMesh sphere = tetseg::test::icosphere(6);
  TriangleMesh cup = translated(tetseg::test::icosphere(4, 0.8), 3.0);
  cup.triangles.erase(std::remove_if(cup.triangles.begin(), cup.triangles.end(),
                                     [&](const Tri& t) {
                                       return cup.vertices[t[0]][2] > 0.6 ||
                                              cup.vertices[t[1]][2] > 0.6 ||
                                              cup.vertices[t[2]][2] > 0.6;
                                     }),
                      cup.triangles.end());
  const TriangleMesh both = joined(sphere, cup);
  const format::Asset asset = surface_asset(both);
  check_surface_asset(both, asset);
  std::size_t open_clusters = 0, closed_with_detector = 0;
  for (std::uint32_t t = 0; t < both.triangles.size(); ++t) {
    const format::Cluster& c = asset.clusters[asset.triangle_cluster[t]];
    const bool overlap_only = (c.flags & format::kClusterOverlapOnly) != 0;
    if (t >= sphere.triangles.size()) {
      REQUIRE(overlap_only);
    } else {
      closed_with_detector += overlap_only ? 0 : 1;
    }
  }
  for (const format::Cluster& c : asset.clusters)
    open_clusters += asset.cluster_triangles[c.triangle_offset] >= sphere.triangles.size() ? 1 : 0;
  CHECK(open_clusters == 1);
  CHECK(closed_with_detector == sphere.triangles.size());
  // A closed component wound inward (a container's shell): one overlap-only cluster, even
  // around the other component.
  TriangleMesh shell = tetseg::test::icosphere(4, 3.0);
  for (Tri& t : shell.triangles) std::swap(t[0], t[1]);
  const TriangleMesh held = joined(shell, sphere);
  const format::Asset in_shell = surface_asset(held);
  check_surface_asset(held, in_shell, &sphere);  // the shell is wound inward
  for (std::uint32_t t = 0; t < held.triangles.size(); ++t) {
    const format::Cluster& c = in_shell.clusters[in_shell.triangle_cluster[t]];
    REQUIRE(((c.flags & format::kClusterOverlapOnly) != 0) == (t < shell.triangles.size()));
  }
  // An open surface alone: every cluster overlap-only.
  const format::Asset open_only = surface_asset(cup);
  check_surface_asset(cup, open_only);
  REQUIRE(open_only.clusters.size() == 1);
  CHECK(open_only.clusters[0].flags == format::kClusterOverlapOnly);
}

TEST_CASE("A surface body refuses what it cannot keep, with the reason", "[surface-body]") {
  const TriangleMesh sphere = tetseg::test::icosphere(3);
  {
    TriangleMesh m = sphere;  // a repeated vertex
    m.triangles[5][1] = m.triangles[5][0];
    CHECK_THAT(refusal(m), Catch::Contains("degenerate triangle 5"));
  }
  {
    TriangleMesh m = sphere;  // zero area: three collinear vertices
    m.vertices.push_back({3.0, 0.0, 0.0});
    m.vertices.push_back({4.0, 0.0, 0.0});
    m.vertices.push_back({5.0, 0.0, 0.0});
    const auto n = static_cast<std::uint32_t>(m.vertices.size());
    m.triangles.push_back({n - 3, n - 2, n - 1});
    CHECK_THAT(refusal(m), Catch::Contains("degenerate triangle"));
  }
  {
    TriangleMesh m = sphere;  // a third triangle on an edge
    const Tri t = m.triangles[0];
    m.vertices.push_back({0.0, 0.0, 3.0});
    m.triangles.push_back({t[0], t[1], static_cast<std::uint32_t>(m.vertices.size() - 1)});
    CHECK_THAT(refusal(m), Catch::Contains("non-manifold edge"));
  }
  {
    TriangleMesh m = sphere;  // one triangle flipped
    std::swap(m.triangles[7][0], m.triangles[7][1]);
    CHECK_THAT(refusal(m), Catch::Contains("not consistently oriented"));
  }
  // Two spheres overlapping: the surface intersects itself.
  CHECK_THAT(refusal(joined(sphere, translated(sphere, 0.5))), Catch::Contains("self-intersects"));
  // A sphere inside another.
  TriangleMesh small = tetseg::test::icosphere(2, 0.3);
  CHECK_THAT(refusal(joined(sphere, small)), Catch::Contains("inside"));
  {
    TriangleMesh m = sphere;
    m.vertices[2][1] = std::nan("");
    CHECK_THAT(refusal(m), Catch::Contains("vertex 2 has a non-finite coordinate"));
  }
  {
    TriangleMesh m = sphere;
    m.triangles[4][2] = 100000;
    CHECK_THAT(refusal(m), Catch::Contains("triangle 4 refers to vertex 100000 out of range"));
  }
  CHECK_THAT(refusal(TriangleMesh{sphere.vertices, {}}), Catch::Contains("no triangles"));
}

TEST_CASE("The build job takes --body and --detectors only in pairs that exist",
          "[surface-body][jobs]") {
  BuildJobOptions options;
  options.build.detectors = format::DetectorForm::kSurfaceWeights;
  CHECK_THROWS_WITH(validate_options(options), Catch::Contains("needs --body surface"));
  options.build.body = format::BodyKind::kSurface;
  CHECK_NOTHROW(validate_options(options));
  options.build.detectors = format::DetectorForm::kTetPoint;
  CHECK_THROWS_WITH(validate_options(options), Catch::Contains("--body surface takes"));
  options.build.detectors.reset();
  CHECK(detector_form_of(options.build) == format::DetectorForm::kSurfaceWeights);
  // A tet mesh is not a surface body's input.
  TetMesh tet;
  tet.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.2, 0.2}};
  tet.tets = {{0, 1, 2, 3}};
  CHECK_THROWS_WITH(build_asset_from_tet_mesh(tet, "tet.mesh", options),
                    Catch::Contains("--body surface builds from a surface"));
}

namespace {

/// `mesh`'s vertices moved by `map`, as the runtime takes them (x, y, z per vertex).
std::vector<double> moved(const TriangleMesh& mesh, const std::function<Vec3(const Vec3&)>& map) {
  std::vector<double> x;
  for (const Vec3& p : mesh.vertices) {
    const Vec3 q = map(p);
    x.insert(x.end(), q.begin(), q.end());
  }
  return x;
}

bool same_contact(const tetseg::Contact& a, const tetseg::Contact& b) {
  return a.kind == b.kind && a.nodes == b.nodes;
}

/// Steps the surface asset through `frames` in rvbc and bvh modes: every step, `any` agrees
/// with the brute-force oracle (testing/scene_oracle.hpp, no culling) and rvbc reports every
/// oracle contact up to the earliest one, with the same earliest time; bvh never reports one
/// the oracle does not. Returns the oracle contacts of the steps compared.
std::size_t compare_with_brute_force(const format::Asset& built,
                                     const std::vector<std::vector<double>>& frames) {
  const std::vector<std::uint8_t> bytes = format::write_asset(built);
  tetseg::Asset asset;
  REQUIRE(tetseg::load_asset(bytes.data(), bytes.size(), asset) == tetseg::Status::kOk);
  tetseg::ColliderOptions rvbc_options, bvh_options;
  rvbc_options.mode = tetseg::ColliderMode::kRvbc;
  bvh_options.mode = tetseg::ColliderMode::kBvh;
  tetseg::Collider rvbc(asset, rvbc_options), bvh(asset, bvh_options);
  REQUIRE(rvbc.status() == tetseg::ColliderStatus::kOk);
  REQUIRE(bvh.status() == tetseg::ColliderStatus::kOk);
  std::size_t total = 0;
  for (std::size_t f = 0; f + 1 < frames.size(); ++f) {
    CAPTURE(f);
    tetseg::test::OracleBody body;
    body.tris = built.triangles.data();
    body.triangle_count = built.triangles.size();
    body.x0 = frames[f].data();
    body.x1 = frames[f + 1].data();
    const std::vector<tetseg::Contact> brute = tetseg::test::scene_brute_contacts({body});
    total += brute.size();
    std::vector<tetseg::Contact> found[2];
    tetseg::Collider* colliders[2] = {&rvbc, &bvh};
    for (int m = 0; m < 2; ++m) {
      REQUIRE(colliders[m]->step(frames[f].data(), frames[f + 1].data()) ==
              tetseg::ColliderStatus::kOk);
      bool any = false;
      REQUIRE(colliders[m]->any_collision(any) == tetseg::ColliderStatus::kOk);
      CHECK(any == !brute.empty());
      found[m].resize(brute.size() + 1024);
      tetseg::ContactsResult r;
      REQUIRE(colliders[m]->contacts(found[m].data(), found[m].size(), r) ==
              tetseg::ColliderStatus::kOk);
      found[m].resize(r.found);
      for (const tetseg::Contact& c : found[m])
        CHECK(std::any_of(brute.begin(), brute.end(),
                          [&](const tetseg::Contact& x) { return same_contact(x, c); }));
    }
    if (brute.empty()) continue;
    REQUIRE(!found[0].empty());
    CHECK(found[0].front().toi == Approx(brute.front().toi).margin(1e-9));
    for (const tetseg::Contact& c : brute) {
      if (c.toi > brute.front().toi + 1e-9) break;
      CHECK(std::any_of(found[0].begin(), found[0].end(),
                        [&](const tetseg::Contact& x) { return same_contact(x, c); }));
    }
  }
  return total;
}

}  // namespace

TEST_CASE("The runtime on a surface body finds what brute force finds while it bends and waves",
          "[surface-body][collider]") {
  const TriangleMesh dumbbell = tetseg::test::dumbbell(0.08);
  const format::Asset asset = surface_asset(dumbbell);
  REQUIRE(check_surface_asset(dumbbell, asset) > 1);
  // Bending: the upper half turns about the x axis, the neck in between blends, until the
  // bulbs touch.
  std::vector<std::vector<double>> bend;
  for (int f = 0; f <= 12; ++f) {
    const double angle = 2.2 * f / 12.0;
    bend.push_back(moved(dumbbell, [&](const Vec3& p) {
      const double s = std::clamp((p[2] + 0.3) / 0.6, 0.0, 1.0);
      const double a = angle * s * s * (3 - 2 * s);
      return Vec3{p[0], std::cos(a) * p[1] - std::sin(a) * p[2],
                  std::sin(a) * p[1] + std::cos(a) * p[2]};
    }));
  }
  CHECK(compare_with_brute_force(asset, bend) > 0);
  // Smooth waves of growing amplitude, each vertex moved by a fixed sinusoidal field.
  std::vector<std::vector<double>> waves;
  for (int f = 0; f <= 8; ++f) {
    const double t = 0.5 * f / 8.0;
    waves.push_back(moved(dumbbell, [&](const Vec3& p) {
      return Vec3{p[0] + t * 0.3 * std::sin(3.1 * p[2] + 0.4),
                  p[1] + t * 0.25 * std::sin(2.3 * p[0] - 1.7 * p[2]),
                  p[2] + t * 0.4 * std::sin(2.9 * p[1] + 0.8)};
    }));
  }
  compare_with_brute_force(asset, waves);
}

namespace {

/// `asset`'s rest positions flattened (x, y, z per node).
std::vector<double> flat_rest(const format::Asset& asset) {
  std::vector<double> x;
  for (const auto& p : asset.rest_positions) x.insert(x.end(), p.begin(), p.end());
  return x;
}

/// Node positions gathered from positions in the file's vertex order; REQUIREs kOk.
std::vector<double> gathered(const format::Asset& asset, const std::vector<double>& source) {
  std::vector<double> out(3 * std::size_t(asset.node_count), -1.0);
  REQUIRE(format::gather_node_positions(asset, source.data(), source.size() / 3, out.data()) ==
          format::GatherStatus::kOk);
  return out;
}

std::string temp_file(const std::string& name, const std::string& text) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("tetseg_surface_body_test_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

}  // namespace

TEST_CASE("A glTF split at seams: its skinned frames, in the file's order, gathered and stepped",
          "[surface-body][skin][source-vertices]") {
  const tetseg::test::SkinnedTube tube =
      tetseg::test::make_skinned_tube({4, 1.0, 0.25, 16, 6, 3, 0.35});
  const tetseg::test::SplitTube split = tetseg::test::split_tube_vertices(tube);
  const tetseg::test::SkinnedTube& file = split.tube;
  REQUIRE(file.vertex_count() > tube.vertex_count());
  const std::string path = temp_file("split.gltf", tetseg::test::tube_gltf(file));
  BuildJobOptions options;
  options.build.body = format::BodyKind::kSurface;
  const BuildJobResult result = build_asset_from_file(path, options);
  // Bone-carried detectors: the seam copies carry equal weights, so the skin is accepted and
  // the map is the same.
  BuildJobOptions skin_options = options;
  skin_options.build.detectors = format::DetectorForm::kBones;
  const BuildJobResult skinned_result = build_asset_from_file(path, skin_options);
  std::filesystem::remove(path);
  CHECK(skinned_result.asset.detector_form == format::DetectorForm::kBones);
  CHECK(skinned_result.asset.source_vertex_nodes == result.asset.source_vertex_nodes);
  const format::Asset& asset = result.asset;
  REQUIRE(format::validate(asset) == format::Status::kOk);
  // The reader merged the copies: one node per position, a map entry per file vertex, and each
  // copy on its original's node.
  CHECK(asset.node_count == tube.vertex_count());
  REQUIRE(asset.source_vertex_nodes.size() == file.vertex_count());
  REQUIRE(format::source_vertex_count(asset) == file.vertex_count());
  std::map<std::uint32_t, std::uint32_t> node_of_original;
  for (std::size_t v = 0; v < file.vertex_count(); ++v) {
    const auto it =
        node_of_original.emplace(split.original_vertex[v], asset.source_vertex_nodes[v]).first;
    CHECK(it->second == asset.source_vertex_nodes[v]);
  }
  CHECK(node_of_original.size() == tube.vertex_count());
  // ... and the file's order is not the nodes' (the copies sit between the originals).
  std::vector<std::uint32_t> identity(asset.node_count);
  std::iota(identity.begin(), identity.end(), 0u);
  CHECK_FALSE(std::equal(identity.begin(), identity.end(), asset.source_vertex_nodes.begin()));
  // The file's rest vertices gathered are the asset's rest positions.
  CHECK(gathered(asset, file.rest) == flat_rest(asset));
  // The round trip keeps the map.
  const std::vector<std::uint8_t> bytes = format::write_asset(asset);
  format::Asset loaded;
  REQUIRE(format::read_asset(bytes.data(), bytes.size(), loaded) == format::Status::kOk);
  CHECK(loaded.source_vertex_nodes == asset.source_vertex_nodes);

  // Frames as an engine skins the file's vertex buffer, gathered, up to the first contact.
  const auto poses = tetseg::test::tube_bend_sequence(file, 25, M_PI / 2, 0.15);
  std::vector<std::vector<double>> frames;
  for (const auto& pose : poses) {
    const std::vector<double> skinned = tetseg::test::skin_tube(file, pose);
    frames.push_back(gathered(asset, skinned));
    // Independent of the map: node n is where every file vertex at its rest position went.
    for (std::size_t v = 0; v < file.vertex_count(); ++v) {
      const std::uint32_t n = asset.source_vertex_nodes[v];
      for (int k = 0; k < 3; ++k) REQUIRE(frames.back()[3 * n + k] == skinned[3 * v + k]);
    }
    if (frames.size() < 2) continue;
    tetseg::test::OracleBody body;
    body.tris = asset.triangles.data();
    body.triangle_count = asset.triangles.size();
    body.x0 = frames[frames.size() - 2].data();
    body.x1 = frames.back().data();
    if (!tetseg::test::scene_brute_contacts({body}).empty()) break;
  }
  REQUIRE(frames.size() < poses.size());  // the tube touched itself
  CHECK(compare_with_brute_force(asset, frames) > 0);

  SECTION("wrong sizes and null pointers are refused, the output untouched") {
    const std::vector<double> skinned = tetseg::test::skin_tube(file, poses.back());
    std::vector<double> out(3 * std::size_t(asset.node_count), 7.0);
    const std::vector<double> before = out;
    const std::size_t n = file.vertex_count();
    CHECK(format::gather_node_positions(asset, skinned.data(), n - 1, out.data()) ==
          format::GatherStatus::kSizeMismatch);
    CHECK(format::gather_node_positions(asset, skinned.data(), asset.node_count, out.data()) ==
          format::GatherStatus::kSizeMismatch);
    CHECK(format::gather_node_positions(asset, nullptr, n, out.data()) ==
          format::GatherStatus::kNullInput);
    CHECK(format::gather_node_positions(asset, skinned.data(), n, nullptr) ==
          format::GatherStatus::kNullInput);
    CHECK(out == before);
  }
}

TEST_CASE("A surface body from STL maps every facet corner to its node",
          "[surface-body][source-vertices]") {
  const TriangleMesh dumbbell = tetseg::test::dumbbell(0.08);
  std::string stl = "solid dumbbell\n";
  char line[256];
  std::vector<double> corners;
  for (const Tri& t : dumbbell.triangles) {
    stl += "facet normal 0 0 0\nouter loop\n";
    for (std::uint32_t v : t) {
      // STL stores float32: the corners are float values, printed exactly (%.17g), so a reader
      // parsing floats or doubles gets them.
      const Vec3& p = dumbbell.vertices[v];
      std::snprintf(line, sizeof line, "vertex %.17g %.17g %.17g\n", double(float(p[0])),
                    double(float(p[1])), double(float(p[2])));
      stl += line;
      for (int k = 0; k < 3; ++k) corners.push_back(double(float(p[k])));
    }
    stl += "endloop\nendfacet\n";
  }
  stl += "endsolid dumbbell\n";
  const std::string path = temp_file("dumbbell.stl", stl);
  BuildJobOptions options;
  options.build.body = format::BodyKind::kSurface;
  const BuildJobResult result = build_asset_from_file(path, options);
  std::filesystem::remove(path);
  const format::Asset& asset = result.asset;
  REQUIRE(format::validate(asset) == format::Status::kOk);
  CHECK(asset.node_count == dumbbell.vertices.size());
  REQUIRE(asset.source_vertex_nodes.size() == 3 * dumbbell.triangles.size());
  // Corner c of facet t is a corner of asset triangle t (the input's order is kept).
  for (std::size_t t = 0; t < dumbbell.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      CHECK(asset.source_vertex_nodes[3 * t + k] == asset.triangles[t][k]);
  CHECK(gathered(asset, corners) == flat_rest(asset));
}
