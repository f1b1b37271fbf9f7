// `tetseg generate`: procedural tet meshes (sphere, ellipsoid, dumbbell, pawn) with CGAL Mesh_3,
// and structured thin shapes (mat, plate, bar, torus, tori) built directly from hexes.
// Also defines the meshing-option and output helpers shared with cmd_tetrahedralize.cpp.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/structured.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {

void print_stage(const preprocess::StageReport& stage) {
  std::fprintf(stderr, "tetseg: %-13s %8.3f s  %s\n", stage.name.c_str(), stage.seconds,
               stage.summary.c_str());
}

namespace mesh_cli {

std::string tet_mesh_summary(const preprocess::TetMesh& mesh) {
  return std::to_string(mesh.nodes.size()) + " nodes, " + std::to_string(mesh.tets.size()) +
         " tets";
}

void add_threads_option(CLI::App& cmd, preprocess::MeshingOptions& m, const std::string& prefix) {
  cmd.add_option("--threads", m.threads,
                 prefix +
                     "Mesh_3 threads: 1 = sequential and reproducible; N > 1 = parallel "
                     "(oneTBB), can be faster on idle cores, but the mesh differs from run to "
                     "run; 0 = all cores")
      ->check(range_check(preprocess::option_ranges::kThreads))
      ->capture_default_str();
}

void add_meshing_options(CLI::App& cmd, preprocess::MeshingOptions& m, MshOutput& msh) {
  cmd.add_option("--cell-size", m.cell_size,
                 "Max tet circumradius (0 = facet size; see docs/cli.md, Meshing options)")
      ->check(range_check(preprocess::option_ranges::kCellSize));
  cmd.add_option("--facet-size", m.facet_size,
                 "Max surface Delaunay-ball radius (0 = cell size, else derived)")
      ->check(range_check(preprocess::option_ranges::kFacetSize));
  cmd.add_option("--facet-distance", m.facet_distance,
                 "Max distance of the meshed surface from the input (0 = facet size / 10)")
      ->check(range_check(preprocess::option_ranges::kFacetDistance));
  cmd.add_option("--facet-angle", m.facet_angle, "Min facet angle in degrees, (0, 30]")
      ->check(CLI::Range(0.01, 30.0));
  cmd.add_option("--radius-edge-ratio", m.cell_radius_edge_ratio,
                 "Tet quality bound (circumradius / shortest edge), >= 2")
      ->check(CLI::Range(2.0, 1000.0));
  cmd.add_flag_callback(
      "--no-optimize", [&m] { m.optimize = false; }, "Skip sliver perturbation and exudation");
  add_threads_option(cmd, m, "");
  CLI::Option* gmsh22 =
      cmd.add_flag("--gmsh22", msh.gmsh22, "Write Gmsh 2.2 instead of 4.1 when the output is .msh");
  cmd.add_flag("--binary", msh.binary, "Write binary Gmsh 4.1 when the output is .msh")
      ->excludes(gmsh22);
}

void check_output_path(const std::string& path) {
  if (!preprocess::is_tet_mesh_path(path))
    throw CLI::ValidationError("--output",
                               "output must end in .mesh, .node, .ele or .msh: " + path);
}

namespace {

void write_one(const std::string& path, const preprocess::TetMesh& mesh, const MshOutput& msh) {
  const bool gmsh = extension_of(path) == ".msh";
  if (gmsh && msh.gmsh22) {
    preprocess::write_gmsh22(path, mesh);
  } else if (gmsh && msh.binary) {
    preprocess::write_gmsh41_binary(path, mesh);
  } else {
    preprocess::write_tet_mesh(path, mesh);
  }
}

/// Writes all files of the output (both of a TetGen pair) or none (write_files_atomic).
void write_atomic(const std::string& output, const preprocess::TetMesh& mesh,
                  const MshOutput& msh) {
  const std::string ext = extension_of(output);
  const std::string stem = output.substr(0, output.size() - ext.size());
  std::vector<std::string> finals = {output};
  if (ext == ".node" || ext == ".ele") finals = {stem + ".node", stem + ".ele"};
  write_files_atomic(finals, [&](const std::vector<std::string>& temps) {
    try {
      write_one(temps.front(), mesh, msh);  // a TetGen writer finds the .ele beside the .node
    } catch (const preprocess::OutputError& e) {
      throw preprocess::OutputError(output, e.what());
    }
  });
}

}  // namespace

void print_retry_note(const std::string& file, const preprocess::TetrahedralizeNotes& notes) {
  std::fprintf(stderr,
               "tetseg: note: %s: the optimised mesh's boundary was not a closed 2-manifold "
               "(%s); meshed again with %s\n",
               base_name(file).c_str(), notes.first_defect.c_str(),
               notes.optimization_used.c_str());
}

void add_time_limit_option(CLI::App& cmd, double& seconds, const std::string& what) {
  cmd.add_option("--time-limit", seconds,
                 "Seconds " + what +
                     " may take (0: no limit); past it the input is refused with exit code 5, "
                     "the stage named and nothing written")
      ->check(range_check(preprocess::option_ranges::kTimeLimit))
      ->capture_default_str();
}

void report_meshing_progress(preprocess::MeshingOptions& m) {
  m.progress = [](double seconds, const std::string& step) {
    std::fprintf(stderr, "tetseg: tetrahedralize: still in %s after %.0f s\n", step.c_str(),
                 seconds);
  };
}

void add_repair_option(CLI::App& cmd, preprocess::MeshingOptions& m) {
  using Repair = preprocess::MeshingOptions::Repair;
  cmd.add_option("--repair", m.repair,
                 "Surface input: none; fix (remove degenerate and duplicate triangles, make "
                 "the orientation consistent, fill small holes, ...); wrap (replace the surface "
                 "by its alpha wrap: closed and manifold for any input); or auto (fix, and wrap "
                 "when what fix leaves cannot be meshed, the reason reported; docs/cli.md)")
      ->transform(CLI::CheckedTransformer(preprocess::name_map<Repair>(), CLI::ignore_case))
      ->option_text(preprocess::name_list<Repair>() + " (" + preprocess::name_of(m.repair) + ")");
  cmd.add_option("--max-deviation", m.max_deviation,
                 "Surface input: how far the asset's surface may be from the input (two-sided "
                 "Hausdorff distance), a fraction of the bounding-box diagonal: bounds the "
                 "derived facet distance (half) and the wrap offset (a quarter); Mesh_3 is rerun "
                 "at smaller sizes (at most twice) while its surface is farther; a mesh still "
                 "farther is reported (report deviation_excess)")
      ->check(range_check(preprocess::option_ranges::kMaxDeviation))
      ->capture_default_str();
  cmd.add_flag("--keep-largest-component", m.keep_largest_component,
               "--repair fix: keep only the connected component of largest area (drops "
               "floating debris and stray parts)");
  cmd.add_option("--wrap-alpha", m.wrap_alpha,
                 "--repair wrap: gaps narrower than this fraction of the bounding-box diagonal "
                 "are closed")
      ->check(range_check(preprocess::option_ranges::kWrapAlpha))
      ->capture_default_str();
  cmd.add_option("--wrap-offset", m.wrap_offset,
                 "--repair wrap: distance of the wrap from the input, as a fraction of the "
                 "bounding-box diagonal")
      ->check(range_check(preprocess::option_ranges::kWrapOffset))
      ->capture_default_str();
  cmd.add_option("--wrap-sheet-offset", m.wrap_sheet_offset,
                 "--repair wrap, an input that encloses no volume (a flat or open sheet): the "
                 "offset of the slab (about twice as thick) it is wrapped into, as a fraction "
                 "of the bounding-box diagonal")
      ->check(range_check(preprocess::option_ranges::kWrapSheetOffset))
      ->capture_default_str();
}

void print_repairs(const std::string& file, const preprocess::TetrahedralizeNotes& notes) {
  if (!notes.fallback_reason.empty())
    std::fprintf(stderr, "tetseg: note: %s: --repair auto wrapped the surface, as fix left: %s\n",
                 base_name(file).c_str(), notes.fallback_reason.c_str());
  if (notes.deviation_excess > 0.0)
    std::fprintf(stderr,
                 "tetseg: note: %s: the meshed surface deviates %.3g of the bounding-box diagonal "
                 "from the input, %.3g over --max-deviation after %zu meshing retries at smaller "
                 "sizes (a sheet wrapped as a slab, a hole closed across, the inner parts of a "
                 "self-intersecting input, or sizes too coarse: a smaller --facet-distance)\n",
                 base_name(file).c_str(),
                 std::max(notes.hausdorff_input_to_mesh, notes.hausdorff_mesh_to_input),
                 notes.deviation_excess, notes.deviation_retries);
  if (notes.repairs.empty()) return;
  std::string list;
  for (const preprocess::RepairCount& r : notes.repairs)
    list += (list.empty() ? "" : ", ") + std::to_string(r.count) + " " + r.kind;
  std::fprintf(stderr, "tetseg: repaired %s: %s\n", base_name(file).c_str(), list.c_str());
  if (notes.hausdorff_input_to_mesh >= 0.0)
    std::fprintf(stderr,
                 "tetseg: note: %s: Hausdorff distance between input and meshed surface: %.3g "
                 "(input to mesh), %.3g (mesh to input), of the bounding-box diagonal\n",
                 base_name(file).c_str(), notes.hausdorff_input_to_mesh,
                 notes.hausdorff_mesh_to_input);
}

void finish_tet_mesh(const preprocess::TetMesh& mesh, const std::string& output,
                     const MshOutput& msh) {
  run_stage("validate", [&](std::string& summary) {
    preprocess::Surface surface;
    try {
      surface = preprocess::extract_valid_surface(mesh, output);
    } catch (const preprocess::InputError& e) {
      throw ToolError(kExitProcessingFailed, output,
                      std::string("meshing produced an invalid mesh: ") + e.what() +
                          " (thin parts may need a smaller --facet-size)");
    }
    summary = std::to_string(surface.triangles.size()) + " surface triangles, " +
              std::to_string(surface.interior_nodes.size()) + " interior nodes";
    return 0;
  });
  run_stage("write", [&](std::string& summary) {
    write_atomic(output, mesh, msh);
    summary = output;
    return 0;
  });
}

}  // namespace mesh_cli

namespace {

struct GenerateArgs {
  std::string shape;
  std::string output;
  preprocess::ShapeOptions shape_options;
  preprocess::StructuredOptions structured;
  std::vector<double> axes;
  preprocess::MeshingOptions meshing;
  mesh_cli::MshOutput msh;
};

void run_generate(const GenerateArgs& args) {
  mesh_cli::check_output_path(args.output);
  preprocess::StructuredShape structured;
  if (preprocess::parse_name(args.shape, structured)) {
    const preprocess::TetMesh mesh = mesh_cli::run_stage("generate", [&](std::string& summary) {
      preprocess::TetMesh m;
      try {
        m = preprocess::generate_structured(structured, args.structured);
      } catch (const std::invalid_argument& e) {
        throw CLI::ValidationError(args.shape, e.what());
      }
      summary = args.shape + ": " + mesh_cli::tet_mesh_summary(m);
      return m;
    });
    mesh_cli::finish_tet_mesh(mesh, args.output, args.msh);
    return;
  }
  preprocess::ShapeOptions shape_options = args.shape_options;
  if (!args.axes.empty())
    for (int k = 0; k < 3; ++k) shape_options.axes[k] = args.axes[static_cast<std::size_t>(k)];
  const preprocess::Shape shape = preprocess::shape_from_name(args.shape);
  const preprocess::TetMesh mesh = mesh_cli::run_stage("generate", [&](std::string& summary) {
    preprocess::TetMesh m = preprocess::generate_shape(shape, shape_options, args.meshing);
    summary = args.shape + ": " + mesh_cli::tet_mesh_summary(m);
    return m;
  });
  mesh_cli::finish_tet_mesh(mesh, args.output, args.msh);
}

}  // namespace

void add_generate_command(CLI::App& root) {
  auto args = std::make_shared<GenerateArgs>();
  CLI::App* cmd = root.add_subcommand(
      "generate",
      "Mesh a procedural shape (sphere, ellipsoid, dumbbell, pawn) into tets, or build a "
      "structured thin one (mat, plate, bar, torus, tori)");
  std::vector<std::string> shapes;
  for (const auto& entry : preprocess::enum_names<preprocess::Shape>())
    shapes.push_back(entry.name);
  for (const auto& entry : preprocess::enum_names<preprocess::StructuredShape>())
    shapes.push_back(entry.name);
  cmd->add_option("shape", args->shape,
                  preprocess::name_list<preprocess::Shape>(" | ") + " | " +
                      preprocess::name_list<preprocess::StructuredShape>(" | "))
      ->required()
      ->check(CLI::IsMember(shapes));
  cmd->add_option("-o,--output", args->output, "Output tet mesh (.mesh, .node/.ele, .msh)")
      ->required();
  cmd->add_option("--size", args->shape_options.size,
                  "Mesh density: 1 = default, 2 = twice as fine along an edge")
      ->check(CLI::Range(0.05, 64.0));
  cmd->add_option("--radius", args->shape_options.radius, "Sphere radius")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--axes", args->axes, "Ellipsoid semi-axes a b c")
      ->expected(3)
      ->check(CLI::PositiveNumber);
  cmd->add_option("--resolution", args->structured.resolution,
                  "mat, plate, bar, torus, tori: hexes along the long direction (0 = the "
                  "shape's default; docs/cli.md)")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--layers", args->structured.layers,
                  "mat, plate, bar, torus, tori: hexes through the thickness (0 = default: 1, "
                  "plate and tori 3)")
      ->check(CLI::Range(0, 64));
  mesh_cli::add_meshing_options(*cmd, args->meshing, args->msh);
  cmd->callback([args] { run_naming_file(args->output, [&] { run_generate(*args); }); });
}

}  // namespace tetseg::tools
