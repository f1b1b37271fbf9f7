// tetseg-scene: writes a generated scene (asset + frame sequence) for benchmarks, demos and
// CLI tests of tetseg-run: closed surfaces of revolution over tet-node ids, clusters cut
// along the axis with detector nodes on it, per-cluster median-split BVHs (the same builder as
// testing/include/tetseg/testing/synthetic_scenes.hpp), and a deforming motion that ends in
// self-contact.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "tetseg/format/asset_io.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tetseg/testing/synthetic_scenes.hpp"
#include "tool_support.hpp"

namespace {

using namespace tetseg::test;
using namespace tetseg::tools;

P3 waves(const P3& p, double t) {
  // Four fixed sinusoidal displacement fields (seedless, reproducible everywhere).
  static const double w[4][7] = {{2.1, -1.3, 0.7, 0.3, 0.6, -0.2, 0.5},
                                 {-0.9, 2.4, 1.1, 1.7, -0.4, 0.7, 0.1},
                                 {1.5, 0.8, -2.2, 2.9, 0.2, 0.3, -0.7},
                                 {-2.6, -0.5, 1.9, 0.4, -0.6, -0.5, 0.4}};
  P3 q = p;
  for (const auto& a : w) {
    const double s = std::sin(a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + a[3]);
    for (int k = 0; k < 3; ++k) q[k] += t * 0.9 * s * a[4 + k];
  }
  return q;
}

void write_obj(const std::string& path, const Surface& s, const std::vector<double>& x) {
  std::string text;
  char buf[128];
  for (std::size_t n = 0; n < x.size() / 3; ++n) {
    std::snprintf(buf, sizeof buf, "v %.17g %.17g %.17g\n", x[3 * n], x[3 * n + 1], x[3 * n + 2]);
    text += buf;
  }
  for (const auto& t : s.tris) {
    std::snprintf(buf, sizeof buf, "f %u %u %u\n", t[0] + 1, t[1] + 1, t[2] + 1);
    text += buf;
  }
  write_file_atomic(path, text);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-scene " TETSEG_VERSION ": generated asset + frame sequence for tetseg-run",
               "tetseg-scene"};
  app.set_version_flag("--version", "tetseg-scene " TETSEG_VERSION);
  std::string shape = "dumbbell", motion, asset_out, frames_out, obj_dir;
  int segments = 32, rings = 40, frame_count = 16;
  app.add_option("shape", shape, "sphere, dumbbell or pawn")
      ->required()
      ->check(CLI::IsMember({"sphere", "dumbbell", "pawn"}));
  app.add_option("asset", asset_out, "Asset file to write")->required();
  app.add_option("frames", frames_out, "Frame-sequence file to write")->required();
  app.add_option("--motion", motion, "press, bend, twist or waves (default: per shape)")
      ->check(CLI::IsMember({"press", "bend", "twist", "waves"}));
  app.add_option("--segments", segments, "Vertices per ring (>= 3)")->check(CLI::Range(3, 4096));
  app.add_option("--rings", rings, "Rings along the axis (>= 2)")->check(CLI::Range(2, 4096));
  app.add_option("--frames", frame_count, "Frames (>= 2)")->check(CLI::Range(2, 100000));
  app.add_option("--obj-dir", obj_dir, "Also write frame_<i>.obj files (all nodes) here");
  return run_tool("tetseg-scene", app, argc, argv, [&] {
    Surface s;
    Scene scene;
    if (shape == "sphere") {
      s = sphere(1.0, segments, rings);
      scene = make_axial_scene(s, {0.0}, {-0.45, 0.45});
      if (motion.empty()) motion = "press";
    } else if (shape == "dumbbell") {
      s = dumbbell(segments, rings);
      scene = make_axial_scene(s, {-0.6, 0.6}, {-1.6, 0.0, 1.6});
      if (motion.empty()) motion = "bend";
    } else {
      s = pawn(segments, rings);
      scene = make_axial_scene(s, {1.0, 2.6}, {0.4, 1.6, 3.3});
      if (motion.empty()) motion = "twist";
    }
    Deformation map = motion == "press"   ? Deformation(press_poles)
                      : motion == "twist" ? Deformation(twist_bend)
                      : motion == "waves" ? Deformation(waves)
                                          : Deformation([](const P3& p, double t) {
                                              return bend_about_x(p, t, 2.6, -0.5, 0.5, 0.0);
                                            });
    const auto frames = make_frames(scene, frame_count, map);
    tetseg::FrameSequence seq;
    seq.node_count = scene.asset.node_count();
    seq.frame_count = static_cast<std::uint32_t>(frames.size());
    for (const auto& f : frames) seq.positions.insert(seq.positions.end(), f.begin(), f.end());
    write_file_atomic(asset_out, tetseg::format::write_asset(scene.asset.data()));
    write_file_atomic(frames_out, tetseg::write_frames(seq));
    if (!obj_dir.empty()) {
      for (std::size_t f = 0; f < frames.size(); ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "/frame_%04zu.obj", f);
        write_obj(obj_dir + name, s, frames[f]);
      }
    }
    std::cerr << "tetseg-scene: " << shape << " (" << motion << "), "
              << scene.asset.triangle_count() << " triangles, " << scene.asset.cluster_count()
              << " clusters, " << frames.size() << " frames\n";
    return kExitOk;
  });
}
