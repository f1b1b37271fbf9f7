// `tetseg tetrahedralize`: a closed surface (OBJ, PLY, STL, OFF, glTF, ...) to a tet mesh with
// CGAL Mesh_3.

#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {

namespace {

struct TetrahedralizeArgs {
  std::string input;
  std::string output;
  preprocess::MeshingOptions meshing;
  mesh_cli::MshOutput msh;
};

void run_tetrahedralize(const TetrahedralizeArgs& args) {
  mesh_cli::check_output_path(args.output);
  const preprocess::TriangleMesh surface = mesh_cli::run_stage("read", [&](std::string& summary) {
    preprocess::TriangleMesh s = preprocess::read_triangle_mesh(args.input);
    summary = std::to_string(s.vertices.size()) + " vertices, " +
              std::to_string(s.triangles.size()) + " triangles (surface)";
    return s;
  });
  preprocess::TetrahedralizeNotes notes;
  preprocess::MeshingOptions meshing = args.meshing;
  mesh_cli::report_meshing_progress(meshing);
  const preprocess::TetMesh mesh = mesh_cli::run_stage("tetrahedralize", [&](std::string& summary) {
    preprocess::TetMesh m = preprocess::tetrahedralize(surface, meshing, args.input, &notes);
    summary = mesh_cli::tet_mesh_summary(m) + ", " + preprocess::deviation_summary(notes);
    return m;
  });
  mesh_cli::print_repairs(args.input, notes);
  if (!notes.optimization_used.empty()) mesh_cli::print_retry_note(args.input, notes);
  mesh_cli::finish_tet_mesh(mesh, args.output, args.msh);
}

}  // namespace

void add_tetrahedralize_command(CLI::App& root) {
  auto args = std::make_shared<TetrahedralizeArgs>();
  CLI::App* cmd = root.add_subcommand(
      "tetrahedralize",
      "Fill a closed triangle surface with tets (CGAL Mesh_3; the boundary is re-meshed)");
  cmd->add_option("surface", args->input, "Closed surface: OBJ, PLY, STL, OFF, glTF, ...")
      ->required();
  cmd->add_option("-o,--output", args->output, "Output tet mesh (.mesh, .node/.ele, .msh)")
      ->required();
  mesh_cli::add_meshing_options(*cmd, args->meshing, args->msh);
  mesh_cli::add_repair_option(*cmd, args->meshing);
  mesh_cli::add_time_limit_option(*cmd, args->meshing.time_limit, "tetrahedralisation");
  cmd->callback([args] { run_naming_file(args->input, [&] { run_tetrahedralize(*args); }); });
}

}  // namespace tetseg::tools
