// tetseg-bench scene (scene_table.hpp).

#include "scene_table.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <tuple>

#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tetseg/runtime/scene.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tool_support.hpp"

namespace tetseg::bench {
namespace {

using Clock = std::chrono::steady_clock;

/// A scene description or a file it names that cannot be used: exit 3 with `message`.
tools::ToolError bad_input(const std::string& message) {
  return tools::ToolError(tools::kExitBadInput, "", message);
}

/// One body of a scene description, with its node range in the frames' global array.
struct DescribedBody {
  bool tet = false;
  std::unique_ptr<Asset> asset;  // tet bodies
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::uint32_t node_count = 0;
  std::size_t offset = 0;
  std::shared_ptr<const BodyShape> shape;
};

struct DescribedScene {
  std::string name;
  std::vector<DescribedBody> bodies;
  FrameSequence frames;
};

/// Reads a scene description (docs/format.md, "Scene descriptions") and its frames.
DescribedScene read_scene(const std::string& name, const std::string& path) {
  std::ifstream in(path);
  if (!in) throw bad_input(path + ": cannot be read");
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  auto resolve = [&](const std::string& p) {
    const std::filesystem::path q(p);
    return (q.is_absolute() ? q : dir / q).string();
  };
  DescribedScene s;
  s.name = name;
  std::string line, frames_path;
  std::size_t line_no = 0, offset = 0;
  auto fail = [&](const std::string& what) {
    return bad_input(path + ": line " + std::to_string(line_no) + ": " + what);
  };
  auto next = [&](std::istringstream& words) {
    if (!std::getline(in, line)) return false;
    ++line_no;
    words = std::istringstream(line);
    return true;
  };
  std::istringstream words;
  std::string key;
  int version = 0;
  if (!next(words) || !(words >> key >> version) || key != "tetseg-scene" || version != 1)
    throw fail("not a scene description (expected 'tetseg-scene 1')");
  while (next(words)) {
    if (!(words >> key)) continue;
    DescribedBody b;
    std::size_t nodes = 0, tris = 0;
    if (key == "frames") {
      if (!(words >> frames_path)) throw fail("frames: missing path");
      continue;
    } else if (key == "tet") {
      std::string asset_path;
      if (!(words >> asset_path >> nodes)) throw fail("expected 'tet ASSET NODES'");
      b.tet = true;
      b.asset = std::make_unique<Asset>();
      std::string why;
      const Status st = load_asset_file(resolve(asset_path), *b.asset, &why);
      if (st != Status::kOk)
        throw bad_input(resolve(asset_path) + ": " + to_string(st) + ": " + why);
      if (b.asset->node_count() != nodes) throw fail("node count differs from the asset's");
      b.triangles.assign(b.asset->data().triangles.begin(), b.asset->data().triangles.end());
      b.shape = BodyShape::from_asset(*b.asset);
    } else if (key == "obstacle") {
      if (!(words >> nodes >> tris) || nodes == 0 || nodes > format::kMaxNodes ||
          tris > format::kMaxTriangles)
        throw fail("expected 'obstacle NODES TRIANGLES'");
      for (std::size_t t = 0; t < tris; ++t) {
        std::array<std::uint32_t, 3> tri{};
        if (!next(words)) throw fail("unexpected end: expected a triangle 'A B C'");
        if (!(words >> tri[0] >> tri[1] >> tri[2])) throw fail("expected a triangle 'A B C'");
        b.triangles.push_back(tri);
      }
      std::vector<std::uint32_t> flat;
      for (const auto& t : b.triangles) flat.insert(flat.end(), t.begin(), t.end());
      b.shape = BodyShape::from_triangles(flat.data(), tris, static_cast<std::uint32_t>(nodes));
      if (!b.shape) throw fail("invalid obstacle triangles");
    } else {
      throw fail("unknown entry '" + key + "'");
    }
    if (!b.shape) throw fail("cannot build the body's topology");
    b.node_count = static_cast<std::uint32_t>(nodes);
    b.offset = offset;
    offset += nodes;
    s.bodies.push_back(std::move(b));
  }
  if (frames_path.empty()) throw bad_input(path + ": no 'frames' entry");
  if (s.bodies.empty()) throw bad_input(path + ": no bodies");
  std::string why;
  const FramesStatus fs = read_frames_file(resolve(frames_path), s.frames, &why);
  if (fs != FramesStatus::kOk)
    throw bad_input(resolve(frames_path) + ": " + to_string(fs) + ": " + why);
  if (s.frames.node_count != offset)
    throw bad_input(resolve(frames_path) + ": " + std::to_string(s.frames.node_count) +
                    " nodes, the description's bodies have " + std::to_string(offset));
  // Obstacles are still: the same positions in every frame.
  for (const DescribedBody& b : s.bodies) {
    if (b.tet) continue;
    for (std::size_t f = 1; f < s.frames.frame_count; ++f)
      if (!std::equal(s.frames.frame(0) + b.offset * 3,
                      s.frames.frame(0) + (b.offset + b.node_count) * 3,
                      s.frames.frame(f) + b.offset * 3))
        throw bad_input(resolve(frames_path) + ": an obstacle moves in frame " + std::to_string(f));
  }
  return s;
}

void require_ok(ColliderStatus st, const std::string& what) {
  if (st != ColliderStatus::kOk) throw bad_input(what + ": " + to_string(st));
}

struct Row {
  std::string name;
  std::size_t bodies = 0, steps = 0;
  double refit = 0, classify = 0, self = 0, pairs = 0, total = 0, merged = 0;
  double pairs_tested = 0, pairs_skipped = 0, contacts = 0, brute_contacts = 0;
  std::uint64_t missed = 0, later_missed = 0, extra = 0;
  std::size_t brute_steps_with_contact = 0, intersecting_frames = 0;
  bool truncated = false;
};

using Key = std::tuple<int, std::uint32_t, std::uint32_t, std::array<std::uint32_t, 4>>;
Key key_of(const Contact& c) {
  return {int(c.kind), c.bodies[0], c.bodies[1], c.nodes};
}

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

Row run_scene(const DescribedScene& s, const SceneTableOptions& o) {
  Row row;
  row.name = s.name;
  row.bodies = s.bodies.size();
  Scene scene;
  for (const DescribedBody& b : s.bodies) {
    BodyOptions bo;
    bo.global_offset = b.offset;
    bo.still = !b.tet;
    bo.self_collision = b.tet;
    require_ok(scene.add_body(b.shape, bo), s.name + ": add body");
  }
  // All surfaces merged into one surface-only body in global node ids, `bvh` mode.
  Scene merged;
  if (o.merged) {
    std::vector<std::uint32_t> flat;
    for (const DescribedBody& b : s.bodies)
      for (const auto& t : b.triangles)
        for (std::uint32_t n : t) flat.push_back(static_cast<std::uint32_t>(b.offset + n));
    const auto shape = BodyShape::from_triangles(flat.data(), flat.size() / 3, s.frames.node_count);
    if (!shape) throw bad_input(s.name + ": cannot merge the surfaces");
    BodyOptions bo;
    bo.mode = ColliderMode::kBvh;
    bo.global_offset = 0;
    require_ok(merged.add_body(shape, bo), s.name + ": add merged body");
  }
  const std::size_t values = std::size_t(s.frames.node_count) * 3;
  std::vector<Contact> buffer(1 << 20), merged_buffer(o.merged ? buffer.size() : 0);
  if (o.expect_clean) {
    for (std::size_t f = 0; f < s.frames.frame_count; ++f) {
      const RestCheck rc = scene.check_rest_intersection(s.frames.frame(f), values);
      require_ok(rc.status, s.name + ": static check of frame " + std::to_string(f));
      if (rc.intersecting) {
        ++row.intersecting_frames;
        std::printf("%s: frame %zu: bodies %u and %u intersect (triangles %u, %u)\n",
                    s.name.c_str(), f, rc.bodies[0], rc.bodies[1], rc.triangle_a, rc.triangle_b);
      }
    }
  }
  for (std::size_t f = 0; f + o.stride < s.frames.frame_count && row.steps < o.max_steps;
       f += o.stride) {
    const double* x0 = s.frames.frame(f);
    const double* x1 = s.frames.frame(f + o.stride);
    double best = INFINITY;
    SceneStats best_stats;
    ContactsResult result;
    for (int r = 0; r < o.repeat; ++r) {
      const Clock::time_point t0 = Clock::now();
      require_ok(scene.step(x0, x1, values), s.name + ": step " + std::to_string(f));
      require_ok(scene.contacts(buffer.data(), buffer.size(), result),
                 s.name + ": contacts of step " + std::to_string(f));
      const double ms = ms_since(t0);
      if (ms < best) {
        best = ms;
        best_stats = scene.stats();
      }
    }
    ++row.steps;
    row.total += best;
    row.refit += best_stats.refit_ms;
    row.classify += best_stats.classify_ms;
    row.self += best_stats.self_ms;
    row.pairs += best_stats.pairs_ms;
    row.pairs_tested += double(best_stats.body_pairs_tested);
    row.pairs_skipped += double(best_stats.body_pairs_skipped);
    row.contacts += double(result.found);
    row.truncated = row.truncated || result.truncated();
    if (o.merged) {
      double best_merged = INFINITY;
      ContactsResult mr;
      for (int r = 0; r < o.repeat; ++r) {
        const Clock::time_point t0 = Clock::now();
        require_ok(merged.step(x0, x1, values), s.name + ": merged step");
        require_ok(merged.contacts(merged_buffer.data(), merged_buffer.size(), mr),
                   s.name + ": merged");
        best_merged = std::min(best_merged, ms_since(t0));
      }
      row.merged += best_merged;
    }
    if (!o.truth) continue;
    std::vector<test::OracleBody> oracle(s.bodies.size());
    for (std::size_t b = 0; b < s.bodies.size(); ++b) {
      const DescribedBody& d = s.bodies[b];
      oracle[b].tris = d.triangles.data();
      oracle[b].triangle_count = d.triangles.size();
      oracle[b].x0 = x0 + d.offset * 3;
      oracle[b].x1 = (d.tet ? x1 : x0) + d.offset * 3;
      oracle[b].self = d.tet;
    }
    const std::vector<Contact> truth = test::scene_brute_contacts(oracle);
    row.brute_contacts += double(truth.size());
    if (!truth.empty()) ++row.brute_steps_with_contact;
    std::set<Key> found, truth_keys;
    for (std::size_t k = 0; k < result.written; ++k) found.insert(key_of(buffer[k]));
    for (const Contact& c : truth) {
      truth_keys.insert(key_of(c));
      if (found.count(key_of(c))) continue;
      // Radial-view culling inside a tet body guarantees the first contact of the step; the
      // scene's other contacts (between bodies, within surface-only bodies) are exact.
      const bool required =
          c.bodies[0] != c.bodies[1] || !s.bodies[c.bodies[0]].tet || c.toi == truth.front().toi;
      ++(required ? row.missed : row.later_missed);
    }
    for (const Key& k : found) row.extra += truth_keys.count(k) ? 0 : 1;
  }
  return row;
}

}  // namespace

int scene_table(const SceneTableOptions& o) {
  if (o.scenes.size() % 2 != 0) {
    std::fprintf(stderr, "tetseg-bench: error: scene: give NAME DESCRIPTION pairs\n");
    return 2;
  }
  if (o.expect_clean && !o.truth) {
    std::fprintf(stderr, "tetseg-bench: error: scene: --expect-clean needs the brute force\n");
    return 2;
  }
  std::vector<Row> rows;
  for (std::size_t i = 0; i < o.scenes.size(); i += 2) {
    const DescribedScene s = read_scene(o.scenes[i], o.scenes[i + 1]);
    rows.push_back(run_scene(s, o));
    std::fprintf(stderr, "tetseg-bench: %s done (%zu steps)\n", s.name.c_str(), rows.back().steps);
  }
  std::printf(
      "| scene | bodies | steps | refit ms | classify ms | self ms | pairs ms | total ms | "
      "merged bvh ms | body pairs tested | skipped | contacts | brute contacts | missed | "
      "later missed (in-body) | extra |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
      "---|---|\n");
  int code = 0;
  for (const Row& r : rows) {
    const double n = r.steps ? double(r.steps) : 1.0;
    char merged[64] = "-";
    if (o.merged)
      std::snprintf(merged, sizeof merged, "%.3f (%.1fx)", r.merged / n,
                    r.total > 0 ? r.merged / r.total : 0.0);
    char truth[128] = "- | - | - | -";
    if (o.truth)
      std::snprintf(truth, sizeof truth, "%.1f | %llu | %llu | %llu", r.brute_contacts / n,
                    static_cast<unsigned long long>(r.missed),
                    static_cast<unsigned long long>(r.later_missed),
                    static_cast<unsigned long long>(r.extra));
    std::printf(
        "| %s | %zu | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | %s | %.1f | %.1f | %.1f%s | "
        "%s |\n",
        r.name.c_str(), r.bodies, r.steps, r.refit / n, r.classify / n, r.self / n, r.pairs / n,
        r.total / n, merged, r.pairs_tested / n, r.pairs_skipped / n, r.contacts / n,
        r.truncated ? " (truncated)" : "", truth);
    if (r.missed > 0 || r.extra > 0) code = 1;
    if (o.expect_clean) {
      std::printf("%s: intersecting frames %zu, steps with brute-force contacts %zu\n",
                  r.name.c_str(), r.intersecting_frames, r.brute_steps_with_contact);
      if (r.intersecting_frames > 0 || r.brute_steps_with_contact > 0) code = 1;
    }
  }
  return code;
}

}  // namespace tetseg::bench
