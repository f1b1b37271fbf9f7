// `tetseg charge`: relative charge density of a tet mesh's boundary or of a closed surface,
// with its equalisation, written as CSV, VTU (ParaView, cell data) or PLY (face colours).

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "mesh_io.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/jobs.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/option_ranges.hpp"
#include "tool_support.hpp"

namespace tetseg::tools {
namespace {

struct ChargeArgs {
  std::string input;
  std::string output;
  std::string report;
  preprocess::ChargeJobOptions job;  ///< the library's defaults
  bool exact_products = false;
};

/// Progress on stderr: a live bar when stderr is a terminal, otherwise a line per quarter.
class Progress {
 public:
  Progress() : m_tty(::isatty(2) != 0) {}
  ~Progress() { finish(); }
  void update(const char* stage, double fraction) {
    const std::string s = stage;
    if (m_tty) {
      const auto now = std::chrono::steady_clock::now();
      if (s == m_stage && fraction < 1.0 && now - m_last < std::chrono::milliseconds(100)) return;
      m_last = now;
      const int width = 30, filled = static_cast<int>(fraction * width + 0.5);
      std::fprintf(stderr, "\rtetseg: charge %-8s [%s%s] %3d%%", stage,
                   std::string(static_cast<std::size_t>(filled), '#').c_str(),
                   std::string(static_cast<std::size_t>(width - filled), ' ').c_str(),
                   static_cast<int>(fraction * 100 + 0.5));
      std::fflush(stderr);
      m_dirty = true;
    } else {
      const int quarter = static_cast<int>(fraction * 4.0);
      if (s != m_stage) m_quarter = -1;
      if (quarter > m_quarter && quarter < 4) {
        std::fprintf(stderr, "tetseg: charge %s %d%%\n", stage, quarter * 25);
        m_quarter = quarter;
      }
    }
    m_stage = s;
  }
  void finish() {
    if (m_dirty) std::fprintf(stderr, "\n");
    m_dirty = false;
  }

 private:
  bool m_tty;
  bool m_dirty = false;
  int m_quarter = -1;
  std::string m_stage;
  std::chrono::steady_clock::time_point m_last{};
};

struct Outputs {
  const std::vector<preprocess::Vec3>& points;
  const std::vector<preprocess::Tri>& triangles;
  const std::vector<double>& density;
  const std::vector<double>& equalized;
};

preprocess::Vec3 centroid_of(const Outputs& o, std::size_t j) {
  const auto& t = o.triangles[j];
  preprocess::Vec3 c{0, 0, 0};
  for (int e = 0; e < 3; ++e) {
    for (int a = 0; a < 3; ++a) c[a] += o.points[t[e]][a] / 3.0;
  }
  return c;
}

double area_of(const Outputs& o, std::size_t j) {
  const auto& t = o.triangles[j];
  const auto& a = o.points[t[0]];
  const auto& b = o.points[t[1]];
  const auto& c = o.points[t[2]];
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double x = u[1] * v[2] - u[2] * v[1], y = u[2] * v[0] - u[0] * v[2],
               z = u[0] * v[1] - u[1] * v[0];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}

/// Used vertices in first-use order and the triangles renumbered over them.
void compact(const Outputs& o, std::vector<preprocess::Vec3>& points,
             std::vector<preprocess::Tri>& triangles) {
  std::vector<std::int64_t> map(o.points.size(), -1);
  triangles = o.triangles;
  for (auto& t : triangles) {
    for (auto& v : t) {
      if (map[v] < 0) {
        map[v] = static_cast<std::int64_t>(points.size());
        points.push_back(o.points[v]);
      }
      v = static_cast<std::uint32_t>(map[v]);
    }
  }
}

std::string format_csv(const Outputs& o) {
  std::string s = "triangle,cx,cy,cz,area,density,equalized\n";
  s.reserve(s.size() + 110 * o.triangles.size());
  // std::to_chars with a precision writes what printf's %.9g writes, several times faster
  // (1.3 M rows: about 1 s with snprintf).
  char number[32];
  auto append = [&](auto value, auto... format) {
    const auto [end, ec] = std::to_chars(number, number + sizeof number, value, format...);
    s.append(number, static_cast<std::size_t>(end - number));
  };
  for (std::size_t j = 0; j < o.triangles.size(); ++j) {
    const auto c = centroid_of(o, j);
    append(j);
    for (const double v : {c[0], c[1], c[2], area_of(o, j), o.density[j], o.equalized[j]}) {
      s += ',';
      append(v, std::chars_format::general, 9);
    }
    s += '\n';
  }
  return s;
}

/// VTK XML unstructured grid of the used vertices and triangles, with `density` and
/// `equalized` as cell data.
std::string format_vtu(const Outputs& o) {
  std::vector<preprocess::Vec3> pts;
  std::vector<preprocess::Tri> tris;
  compact(o, pts, tris);
  io::UnstructuredGrid grid;
  grid.points = pts;
  for (const auto& t : tris) {
    grid.cell_types.push_back(5);
    grid.cells.push_back({t[0], t[1], t[2]});
  }
  grid.cell_data = {{"density", "Float64", o.density}, {"equalized", "Float64", o.equalized}};
  return io::vtu_text(grid);
}

/// ASCII PLY, faces in gray levels of the equalised density (the paper's Fig. 4 encoding:
/// darker = less charge), plus the two values as face properties.
std::string format_ply(const Outputs& o) {
  io::PlyOutMesh ply;
  ply.comment = "tetseg charge: gray = equalized density";
  compact(o, ply.vertices, ply.triangles);
  std::vector<double> gray;
  for (const double e : o.equalized) gray.push_back(std::lround(std::clamp(e, 0.0, 1.0) * 255.0));
  ply.face_properties = {{"red", "uchar", gray},
                         {"green", "uchar", gray},
                         {"blue", "uchar", gray},
                         {"density", "double", o.density},
                         {"equalized", "double", o.equalized}};
  return io::ply_text(ply);
}

void run_charge(const ChargeArgs& args) {
  const std::string ext = extension_of(args.output);
  if (ext != ".csv" && ext != ".vtu" && ext != ".ply") {
    throw CLI::ValidationError("--output", "output must end in .csv, .vtu or .ply: " + args.output);
  }
  preprocess::ChargeJobOptions options = args.job;
  options.charge.relaxed_products = !args.exact_products;
  Progress progress;
  options.charge.progress = [&](const char* stage, double f) { progress.update(stage, f); };
  preprocess::ChargeJobResult result =
      preprocess::charge_from_file(args.input, options, [&](const preprocess::StageReport& stage) {
        progress.finish();
        print_stage(stage);
      });
  const preprocess::ChargeResult& r = result.charge;
  if (!r.converged) {
    std::fprintf(stderr,
                 "tetseg: warning: the solver stopped at residual %.2e above the tolerance %.2e "
                 "after %d iterations (raise --max-iterations)\n",
                 r.residual, r.tolerance, r.iterations);
  }
  preprocess::StageTimer(result.report, print_stage).run("write", [&](std::string& summary) {
    const Outputs out{result.points, result.triangles, r.density, result.equalized};
    const std::string text =
        ext == ".csv" ? format_csv(out) : (ext == ".vtu" ? format_vtu(out) : format_ply(out));
    write_file_atomic(args.output, text);
    summary = args.output;
    return 0;
  });
  if (!args.report.empty())
    write_file_atomic(args.report, preprocess::charge_report_json(result, args.input));
}

}  // namespace

void add_charge_command(CLI::App& root) {
  auto args = std::make_shared<ChargeArgs>();
  CLI::App* cmd = root.add_subcommand(
      "charge", "Charge density of a tet mesh's boundary or a closed surface (as given)");
  cmd->add_option("input", args->input,
                  "Tet mesh (.mesh, .node/.ele, .msh) or closed surface (.off, .obj, .ply, ...)")
      ->required();
  cmd->add_option("-o,--output", args->output,
                  "Per-triangle output: .csv (triangle,cx,cy,cz,area,density,equalized), "
                  ".vtu (cell data) or .ply (gray faces)")
      ->required();
  cmd->add_option("--solver", args->job.charge.solver, "Charge solver")
      ->transform(CLI::CheckedTransformer(preprocess::name_map<preprocess::ChargeSolver>()))
      ->option_text(preprocess::name_list<preprocess::ChargeSolver>() + " (auto)");
  cmd->add_option("--tolerance", args->job.charge.tolerance,
                  "Relative residual of the iterative solvers (0: 1e-6 below 10k triangles, "
                  "1e-8 above)")
      ->check(range_check(preprocess::option_ranges::kTolerance));
  cmd->add_option("--max-iterations", args->job.charge.max_iterations, "Iteration cap")
      ->check(range_check(preprocess::option_ranges::kMaxIterations));
  cmd->add_option(
         "--theta", args->job.charge.fast_theta,
         "Fast solver opening parameter, (0, 0.95] (0: 0.4 below 10k triangles, 0.45 above)")
      ->check(range_check(preprocess::option_ranges::kTheta));
  cmd->add_option("--order", args->job.charge.fast_order,
                  "Fast solver expansion order (-1 = 6 below 10k triangles, else 8)")
      ->check(range_check(preprocess::option_ranges::kOrder));
  cmd->add_flag("--exact-products", args->exact_products,
                "Fast solver: every GMRES product at --order and --theta (default: once the "
                "residual is small, a cheaper order-4 FMM within half the tolerance; "
                "docs/charge.md)");
  cmd->add_option("--equalization,--equalize", args->job.equalization,
                  "histogram (the paper), rank or log-histogram (alias log)")
      ->transform(CLI::CheckedTransformer(preprocess::name_map<preprocess::Equalization>()))
      ->option_text(preprocess::name_list<preprocess::Equalization>() + " (histogram)");
  cmd->add_option("--bins", args->job.bins, "Histogram bins")
      ->check(range_check(preprocess::option_ranges::kBins));
  cmd->add_option("--report", args->report, "Write a JSON report (solver, iterations, times)");
  cmd->callback([args] { run_naming_file(args->input, [&] { run_charge(*args); }); });
}

}  // namespace tetseg::tools
