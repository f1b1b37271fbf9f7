// tetseg-sim: drops soft tet meshes on the ground and still obstacles and writes the frame sequence
// (docs/simulation.md). Exit codes: docs/cli.md (0 ok, 2 usage, 3 bad input, 4 output).

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "sim.hpp"
#include "tetseg/format/asset.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/runtime/frames.hpp"
#include "tetseg/testing/scene_oracle.hpp"
#include "tool_support.hpp"

namespace {

using namespace tetseg::tools;
constexpr const char* kTool = "tetseg-sim";

/// The preprocess library's errors as the exit codes of docs/cli.md, naming the file without
/// its directories (run_tool's hook).
void rethrow_preprocess_error_as_tool_error() {
  try {
    throw;
  } catch (const tetseg::preprocess::InputError& e) {
    throw ToolError(kExitBadInput, base_name(e.file()), e.what());
  } catch (const tetseg::preprocess::OutputError& e) {
    throw ToolError(kExitOutputFailed, base_name(e.file()), e.what());
  }
}

struct Args {
  std::string mesh, asset, output, scene_out, queries_out, mode = "rvbc";
  std::uint32_t record_every = 1;
  std::vector<std::string> bodies, boxes, bins, spheres;
  std::uint32_t frames = 100;
  std::uint32_t obstacle_resolution = 8;
  double drop = 0.2, tilt_x = 0.0, tilt_y = 0.0;
  bool json = false;
};

/// Comma-separated numbers of an option value; `count` of them required (or between `min` and
/// `count` when min > 0).
std::vector<double> numbers(const std::string& option, const std::string& value, std::size_t min,
                            std::size_t count) {
  std::vector<double> out;
  std::stringstream in(value);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v))
      throw ToolError(kExitUsage, "", option + " " + value + ": '" + item + "' is not a number");
    out.push_back(v);
  }
  if (out.size() < min || out.size() > count)
    throw ToolError(
        kExitUsage, "",
        option + " " + value + ": expected " + std::to_string(count) + " comma-separated numbers");
  return out;
}

/// One soft body of the command line: mesh, asset and placement.
struct BodySpec {
  std::string mesh, asset;
  double drop, tilt_x, tilt_y;
  bool place_horizontally = false;
  double horizontal[2] = {0, 0};
};

/// `MESH,ASSET[,DROP[,H1,H2[,TILT_X,TILT_Y]]]` (defaults: --drop, --tilt-x, --tilt-y).
BodySpec parse_body(const std::string& value, const Args& a) {
  const std::size_t c1 = value.find(',');
  if (c1 == std::string::npos)
    throw ToolError(kExitUsage, "", "--body " + value + ": expected MESH,ASSET[,DROP[,H1,H2]]");
  const std::size_t c2 = value.find(',', c1 + 1);
  BodySpec b{value.substr(0, c1), value.substr(c1 + 1, c2 == std::string::npos ? c2 : c2 - c1 - 1),
             a.drop, a.tilt_x, a.tilt_y};
  if (c2 == std::string::npos) return b;
  const std::vector<double> v = numbers("--body", value.substr(c2 + 1), 1, 5);
  if (v.size() == 2 || v.size() == 4)
    throw ToolError(kExitUsage, "", "--body " + value + ": give DROP, DROP,H1,H2 or all five");
  if (v[0] < 0) throw ToolError(kExitUsage, "", "--body " + value + ": negative drop");
  b.drop = v[0];
  if (v.size() >= 3) {
    b.place_horizontally = true;
    b.horizontal[0] = v[1];
    b.horizontal[1] = v[2];
  }
  if (v.size() == 5) {
    b.tilt_x = v[3];
    b.tilt_y = v[4];
  }
  return b;
}

/// A still obstacle from a generated surface moved by `shift`.
Obstacle obstacle_of(const tetseg::test::Surface& s, const tetseg::test::P3& shift) {
  Obstacle o;
  for (const auto& p : s.verts)
    for (int k = 0; k < 3; ++k) o.positions.push_back(p[k] + shift[k]);
  o.triangles.assign(s.tris.begin(), s.tris.end());
  return o;
}

Obstacle box_obstacle(const std::string& option, const std::string& value, int open_side,
                      int resolution) {
  const std::vector<double> v = numbers(option, value, 6, 6);
  for (int k = 0; k < 3; ++k)
    if (!(v[k] < v[k + 3]))
      throw ToolError(kExitUsage, "", option + " " + value + ": need MIN < MAX on every axis");
  return obstacle_of(
      tetseg::test::box_surface({v[0], v[1], v[2]}, {v[3], v[4], v[5]}, resolution, open_side),
      {0, 0, 0});
}

Obstacle sphere_obstacle(const std::string& value, int resolution) {
  const std::vector<double> v = numbers("--sphere", value, 4, 4);
  if (!(v[3] > 0)) throw ToolError(kExitUsage, "", "--sphere " + value + ": radius must be > 0");
  return obstacle_of(tetseg::test::sphere(v[3], 4 * resolution, 2 * resolution),
                     {v[0], v[1], v[2]});
}

/// `path` relative to the folder of `from` (a file), for the scene description.
std::string relative_to(const std::string& path, const std::string& from) {
  namespace fs = std::filesystem;
  const fs::path base = fs::absolute(fs::path(from)).parent_path();
  return fs::absolute(fs::path(path)).lexically_normal().lexically_relative(base).string();
}

int run(const Args& a, SimOptions opt) {
  if (!tetseg::parse_collider_mode(a.mode.c_str(), opt.collider_mode))
    throw ToolError(kExitUsage, "", "unknown mode '" + a.mode + "'");
  std::vector<BodySpec> specs;
  if (!a.mesh.empty() || !a.asset.empty()) {
    if (a.mesh.empty() || a.asset.empty())
      throw ToolError(kExitUsage, "", "give both MESH and ASSET, or --body");
    specs.push_back({a.mesh, a.asset, a.drop, a.tilt_x, a.tilt_y});
  }
  for (const std::string& b : a.bodies) specs.push_back(parse_body(b, a));
  if (specs.empty()) throw ToolError(kExitUsage, "", "no soft body: give MESH ASSET or --body");
  const int resolution = static_cast<int>(a.obstacle_resolution);
  std::vector<std::pair<Obstacle, std::string>> obstacles;
  for (const std::string& v : a.boxes)
    obstacles.push_back({box_obstacle("--box", v, -1, resolution), "--box " + v});
  for (const std::string& v : a.bins)
    obstacles.push_back({box_obstacle("--bin", v, opt.up_axis, resolution), "--bin " + v});
  for (const std::string& v : a.spheres)
    obstacles.push_back({sphere_obstacle(v, resolution), "--sphere " + v});

  // Meshes and assets read once per file (a pile repeats one ball).
  std::map<std::string, tetseg::preprocess::TetMesh> meshes;
  std::map<std::string, std::unique_ptr<tetseg::Asset>> assets;
  Simulation sim(opt);
  std::ostringstream scene;
  scene << "tetseg-scene 1\n";
  if (!a.scene_out.empty()) scene << "frames " << relative_to(a.output, a.scene_out) << "\n";
  for (const BodySpec& b : specs) {
    if (!meshes.count(b.mesh)) meshes[b.mesh] = tetseg::preprocess::read_tet_mesh(b.mesh);
    if (!assets.count(b.asset)) {
      auto asset = std::make_unique<tetseg::Asset>();
      std::string why;
      const tetseg::Status s = tetseg::load_asset_file(b.asset, *asset, &why);
      if (s != tetseg::Status::kOk)
        throw ToolError(kExitBadInput, b.asset, std::string(tetseg::to_string(s)) + ": " + why);
      assets[b.asset] = std::move(asset);
    }
    const tetseg::preprocess::TetMesh& mesh = meshes[b.mesh];
    std::vector<double> start =
        place_above_ground(mesh.nodes, opt.up_axis, opt.ground, b.drop, b.tilt_x, b.tilt_y);
    if (b.place_horizontally) {
      for (int j = 0; j < 2; ++j) {
        const int axis = (opt.up_axis + 1 + j) % 3;
        double centre = 0;
        for (std::size_t i = 0; i < mesh.nodes.size(); ++i) centre += start[i * 3 + axis];
        centre /= double(std::max<std::size_t>(1, mesh.nodes.size()));
        for (std::size_t i = 0; i < mesh.nodes.size(); ++i)
          start[i * 3 + axis] += b.horizontal[j] - centre;
      }
    }
    sim.add_body(mesh, *assets[b.asset], start, b.mesh);
    scene << "tet " << (a.scene_out.empty() ? b.asset : relative_to(b.asset, a.scene_out)) << " "
          << mesh.nodes.size() << "\n";
  }
  for (auto& [o, what] : obstacles) {
    scene << "obstacle " << o.positions.size() / 3 << " " << o.triangles.size() << "\n";
    for (const auto& t : o.triangles) scene << t[0] << " " << t[1] << " " << t[2] << "\n";
    sim.add_obstacle(std::move(o), what);
  }
  sim.check_start();

  tetseg::FrameSequence seq;
  if (sim.node_count() > tetseg::format::kMaxNodes)
    throw ToolError(kExitUsage, "", "too many nodes in the scene");
  seq.node_count = static_cast<std::uint32_t>(sim.node_count());
  seq.frame_count = a.frames;
  seq.positions.reserve(std::size_t(a.frames) * seq.node_count * 3);
  sim.append_positions(seq.positions);
  tetseg::FrameSequence queries;
  queries.node_count = seq.node_count;
  if (!a.queries_out.empty()) sim.record_queries(&queries.positions, a.record_every);
  for (std::uint32_t f = 1; f < a.frames; ++f) {
    sim.advance_frame();
    sim.append_positions(seq.positions);
  }
  if (!a.queries_out.empty()) {  // checked before anything is written
    const SimCounters& c = sim.counters();
    if (c.queries_recorded == 0)
      throw ToolError(kExitProcessingFailed, a.queries_out,
                      "no substep had a contact: no query step to record");
    if (c.queries_recorded * 2 > 0xffffffffull)
      throw ToolError(kExitProcessingFailed, a.queries_out, "too many query steps to record");
    queries.frame_count = static_cast<std::uint32_t>(c.queries_recorded * 2);
  }
  write_file_atomic(a.output, tetseg::write_frames(seq));
  if (!a.queries_out.empty()) write_file_atomic(a.queries_out, tetseg::write_frames(queries));
  if (!a.scene_out.empty()) write_file_atomic(a.scene_out, scene.str());
  const SimCounters& c = sim.counters();
  if (a.json) {
    std::cout << "{\"frames\": " << a.frames << ", \"nodes\": " << seq.node_count
              << ", \"bodies\": " << specs.size() << ", \"obstacles\": " << obstacles.size()
              << ", \"substeps\": " << c.substeps
              << ", \"substeps_with_contact\": " << c.substeps_with_contact
              << ", \"contacts_resolved\": " << c.contacts_resolved
              << ", \"body_contacts\": " << c.body_contacts
              << ", \"query_rounds\": " << c.query_rounds << ", \"max_rounds\": " << c.max_rounds
              << ", \"nodes_frozen\": " << c.nodes_frozen
              << ", \"ground_contacts\": " << c.ground_contacts
              << ", \"queries_recorded\": " << c.queries_recorded << "}\n";
  } else {
    std::fprintf(stderr,
                 "tetseg-sim: %u frames, %llu substeps; contact: %llu contacts resolved (%llu "
                 "between bodies) in %llu substeps (%llu node freezes, at most %u query rounds "
                 "per substep)\n",
                 a.frames, static_cast<unsigned long long>(c.substeps),
                 static_cast<unsigned long long>(c.contacts_resolved),
                 static_cast<unsigned long long>(c.body_contacts),
                 static_cast<unsigned long long>(c.substeps_with_contact),
                 static_cast<unsigned long long>(c.nodes_frozen), c.max_rounds);
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-sim " TETSEG_VERSION
               ": drops soft tet meshes on the ground and still obstacles; writes a frame "
               "sequence whose every substep is free of collisions (docs/simulation.md)",
               "tetseg-sim"};
  app.set_version_flag("--version", "tetseg-sim " TETSEG_VERSION);
  Args a;
  SimOptions opt;
  app.add_option("mesh", a.mesh, "Tet mesh (.mesh, .node/.ele, .msh) of the first soft body");
  app.add_option("asset", a.asset, "Asset built from the same mesh (tetseg build)");
  app.add_option("--body", a.bodies,
                 "Another soft body: MESH,ASSET[,DROP[,H1,H2[,TILT_X,TILT_Y]]] (H1, H2: centroid "
                 "on the axes after --up; repeatable)")
      ->allow_extra_args(false);
  app.add_option("--box", a.boxes, "Still closed box MIN_X,MIN_Y,MIN_Z,MAX_X,MAX_Y,MAX_Z")
      ->allow_extra_args(false);
  app.add_option("--bin", a.bins, "Still box open at the top (same six numbers)")
      ->allow_extra_args(false);
  app.add_option("--sphere", a.spheres, "Still sphere CX,CY,CZ,R")->allow_extra_args(false);
  app.add_option("--obstacle-resolution", a.obstacle_resolution,
                 "Obstacle tessellation: quads per box edge, sphere rings / 2 (default 8)")
      ->check(CLI::Range(1u, 256u));
  app.add_option("--scene", a.scene_out,
                 "Scene description to write for tetseg-bench scene (docs/format.md)");
  app.add_option("-o,--output", a.output, "Frame-sequence file to write")->required();
  app.add_option(
      "--record-queries", a.queries_out,
      "Also write the collision queries of substeps with contact as a frame-pair file "
      "(frames 2i, 2i+1: start and predicted end of query i; tetseg-bench table --pairs)");
  app.add_option("--record-every", a.record_every,
                 "Record every N-th substep with contact (default 1)")
      ->check(CLI::Range(1u, 1000000u));
  app.add_option("--frames", a.frames, "Frames to write, including the start (default 100)")
      ->check(CLI::Range(1u, 100000u));
  app.add_option("--substeps", opt.substeps, "Substeps per frame (default 4)")
      ->check(CLI::Range(1u, 1000u));
  app.add_option("--iterations", opt.iterations, "Constraint sweeps per substep (default 1)")
      ->check(CLI::Range(1u, 100u));
  app.add_option("--dt", opt.frame_dt, "Seconds per frame (default 1/60)")
      ->check(CLI::PositiveNumber);
  app.add_option("--drop", a.drop, "Start height of the lowest point above the ground")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--tilt-x", a.tilt_x, "Rotation about the x axis in degrees before the drop");
  app.add_option("--tilt-y", a.tilt_y, "Then rotation about the y axis in degrees");
  app.add_option("--up", opt.up_axis, "Up axis: 0 = x, 1 = y, 2 = z (default)")
      ->check(CLI::Range(0, 2));
  app.add_option("--gravity", opt.gravity, "Gravity along -up (default 9.81)");
  app.add_option("--friction", opt.friction, "Ground friction coefficient (default 0.5)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--edge-compliance", opt.edge_compliance,
                 "XPBD compliance of edge lengths (softer when larger; default 1e-4)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--volume-compliance", opt.volume_compliance,
                 "XPBD compliance of tet volumes (default 0)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--damping", opt.damping, "Velocity damping per second (default 0.5)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--mode", a.mode, "Self-contact mode of the soft bodies: rvbc (default), bvh")
      ->check(CLI::IsMember({"rvbc", "bvh"}));
  app.add_flag("--no-self-contact{false}", opt.self_contact,
               "Skip all contact handling (frames may intersect; for comparisons)");
  app.add_option("--twist", opt.twist_rate,
                 "Twist every soft body by its ends: degrees per second the two ends turn "
                 "against each other (default 0: off)");
  app.add_option("--twist-axis", opt.twist_axis, "Twist axis: 0 = x (default), 1 = y, 2 = z")
      ->check(CLI::Range(0, 2));
  app.add_option("--twist-ends", opt.twist_ends,
                 "Share of the body's length held at each end (default 0.05)")
      ->check(CLI::Range(0.001, 0.499));
  app.add_flag("--json", a.json, "Print the counters as JSON on stdout");
  return run_tool(
      kTool, app, argc, argv, [&] { return run(a, opt); }, "",
      rethrow_preprocess_error_as_tool_error);
}
