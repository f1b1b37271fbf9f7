// tetseg-character: writes the generated skinned test character (a capped tube on a chain of
// bones, tetseg/testing/skinned_tube.hpp) as glTF 2.0 with its skin, and a bending sequence:
// the surface vertices per frame (linear blend skinning in double) and the bones' skinning
// matrices per frame (for bone-carried detectors, format::skinned_detector_positions).
//
//   tetseg-character -o PREFIX   ->   PREFIX.gltf, PREFIX.tsf, PREFIX.bones.tsf

#include <cmath>
#include <cstdio>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "tetseg/runtime/frames.hpp"
#include "tetseg/testing/skinned_tube.hpp"
#include "tool_support.hpp"

namespace {

using namespace tetseg::tools;
constexpr const char* kTool = "tetseg-character";

struct Args {
  std::string prefix;
  tetseg::test::SkinnedTubeOptions tube;
  std::uint32_t frames = 61;
  double max_angle = 90.0;  // degrees
  double wobble = 10.0;     // degrees
};

int run(const Args& a) {
  const tetseg::test::SkinnedTube tube = tetseg::test::make_skinned_tube(a.tube);
  const auto poses = tetseg::test::tube_bend_sequence(tube, a.frames, a.max_angle * M_PI / 180,
                                                      a.wobble * M_PI / 180);
  tetseg::FrameSequence surface, bones;
  surface.node_count = static_cast<std::uint32_t>(tube.vertex_count());
  bones.node_count = 4 * tube.options.bones;  // 12 doubles per bone: 4 "nodes" of 3
  surface.frame_count = bones.frame_count = a.frames;
  for (const auto& matrices : poses) {
    const std::vector<double> x = tetseg::test::skin_tube(tube, matrices);
    surface.positions.insert(surface.positions.end(), x.begin(), x.end());
    for (const auto& m : matrices)
      bones.positions.insert(bones.positions.end(), m.begin(), m.end());
  }
  const std::string gltf = tetseg::test::tube_gltf(tube);
  const auto surface_bytes = tetseg::write_frames(surface);
  const auto bone_bytes = tetseg::write_frames(bones);
  const std::vector<std::string> paths = {a.prefix + ".gltf", a.prefix + ".tsf",
                                          a.prefix + ".bones.tsf"};
  write_files_atomic(paths, [&](const std::vector<std::string>& tmp) {
    auto write = [](const std::string& path, const void* data, std::size_t size) {
      std::FILE* f = std::fopen(path.c_str(), "wb");
      if (f == nullptr) throw ToolError(kExitOutputFailed, path, "cannot open for writing");
      const bool ok = std::fwrite(data, 1, size, f) == size;
      if (std::fclose(f) != 0 || !ok) throw ToolError(kExitOutputFailed, path, "write failed");
    };
    write(tmp[0], gltf.data(), gltf.size());
    write(tmp[1], surface_bytes.data(), surface_bytes.size());
    write(tmp[2], bone_bytes.data(), bone_bytes.size());
  });
  std::printf("%s: %zu vertices, %zu triangles, %u bones, %u frames\n", kTool, tube.vertex_count(),
              tube.triangles.size(), tube.options.bones, a.frames);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-character " TETSEG_VERSION
               ": the generated skinned test character (a capped tube on a chain of bones) as "
               "glTF with a skin, and a sequence bending it at the joints until it touches "
               "itself: PREFIX.gltf, PREFIX.tsf (surface vertices per frame), PREFIX.bones.tsf "
               "(per frame, each bone's row-major 3x4 skinning matrix as 4 points)",
               "tetseg-character"};
  app.set_version_flag("--version", "tetseg-character " TETSEG_VERSION);
  Args a;
  app.add_option("-o,--output", a.prefix, "Output prefix")->required();
  app.add_option("--bones", a.tube.bones, "Bones along the tube (default 4)")
      ->check(CLI::Range(1u, 64u));
  app.add_option("--around", a.tube.around, "Vertices per ring (default 24)")
      ->check(CLI::Range(3u, 4096u));
  app.add_option("--rings-per-bone", a.tube.rings_per_bone, "Rings per bone (default 8)")
      ->check(CLI::Range(1u, 4096u));
  app.add_option("--joint-pinch", a.tube.joint_pinch,
                 "The tube narrows to (1 - this) x its radius at each joint (default 0.3)")
      ->check(CLI::Range(0.0, 0.9));
  app.add_option("--frames", a.frames, "Frames, the rest pose first (default 61)")
      ->check(CLI::Range(2u, 100000u));
  app.add_option("--max-angle", a.max_angle,
                 "Bend of every joint in the last frame, degrees (default 90)")
      ->check(CLI::Range(-360.0, 360.0));
  app.add_option("--wobble", a.wobble,
                 "Out-of-plane swing of the joints at mid-sequence, degrees (default 10)")
      ->check(CLI::Range(-90.0, 90.0));
  return run_tool(kTool, app, argc, argv, [&] { return run(a); });
}
