// tetseg-bench-charge: run time, iterations, peak memory and error of each charge solver on
// ellipsoids (analytic density) and a subdivided CGAL demo mesh. Each case runs in a child
// process so its peak RSS can be measured (wait4). Prints a Markdown table.

#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "../preprocess/src/charge_solvers.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/option_ranges.hpp"
#include "tetseg/testing/charge_shapes.hpp"
#include "tool_support.hpp"

using namespace tetseg;
using namespace tetseg::tools;
using preprocess::ChargeOptions;
using preprocess::ChargeSolver;
using preprocess::TriangleMesh;

namespace {

constexpr const char* kTool = "tetseg-bench-charge";

struct CaseResult {
  bool ok = false;
  double assembly = 0, solve = 0, residual = 0, capacitance = 0, exact_residual = -1;
  int iterations = 0, relaxed = 0;
  long peak_kb = 0;
  double cpu = 0;  ///< user + system seconds of the child (all threads)
  char solver[16] = {};
  char error[200] = {};
  std::vector<double> density;
};

bool read_all(int fd, void* data, std::size_t size) {
  auto* p = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t got = ::read(fd, p, size);
    if (got <= 0) return false;
    p += got;
    size -= static_cast<std::size_t>(got);
  }
  return true;
}

void write_all(int fd, const void* data, std::size_t size) {
  const auto* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t put = ::write(fd, p, size);
    if (put <= 0) return;
    p += put;
    size -= static_cast<std::size_t>(put);
  }
}

/// Relative residual ||1 - M y|| / ||1|| of a computed density against the exact collocation
/// matrix (O(N^2) product): y = density * C / total area.
double exact_residual(const TriangleMesh& m, const std::vector<double>& density,
                      double capacitance);

double cpu_seconds(const struct rusage& usage) {
  return static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

/// Runs compute_charge in a child process (no OpenMP may run in the parent before a fork);
/// returns its results and peak RSS, and with `exact` the residual against the exact matrix
/// (computed in the child after the timed solve; not part of "CPU s").
CaseResult run_case(const TriangleMesh& mesh, const ChargeOptions& options, bool exact = false) {
  int fds[2];
  CaseResult r;
  if (::pipe(fds) != 0) return r;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    struct Header {
      int ok, iterations, relaxed;
      double assembly, solve, residual, capacitance, cpu, exact_residual;
      char solver[16], error[200];
    } h{};
    h.exact_residual = -1.0;
    std::vector<double> density;
    try {
      const auto c = preprocess::compute_charge(mesh.vertices, mesh.triangles, options);
      h.ok = 1;
      h.iterations = c.iterations;
      h.relaxed = c.relaxed_products;
      h.assembly = c.assembly_seconds;
      h.solve = c.solve_seconds;
      h.residual = c.residual;
      h.capacitance = c.capacitance;
      std::snprintf(h.solver, sizeof h.solver, "%s", c.solver.c_str());
      density = c.density;
      struct rusage self {};
      ::getrusage(RUSAGE_SELF, &self);
      h.cpu = cpu_seconds(self);
      if (exact) h.exact_residual = exact_residual(mesh, c.density, c.capacitance);
    } catch (const std::exception& e) {
      std::snprintf(h.error, sizeof h.error, "%s", e.what());
    }
    write_all(fds[1], &h, sizeof h);
    const std::size_t n = density.size();
    write_all(fds[1], &n, sizeof n);
    write_all(fds[1], density.data(), n * sizeof(double));
    ::close(fds[1]);
    ::_exit(0);
  }
  ::close(fds[1]);
  struct {
    int ok, iterations, relaxed;
    double assembly, solve, residual, capacitance, cpu, exact_residual;
    char solver[16], error[200];
  } h{};
  std::size_t n = 0;
  if (read_all(fds[0], &h, sizeof h) && read_all(fds[0], &n, sizeof n)) {
    r.density.resize(n);
    read_all(fds[0], r.density.data(), n * sizeof(double));
  }
  ::close(fds[0]);
  int status = 0;
  struct rusage usage {};
  ::wait4(pid, &status, 0, &usage);
  r.ok = h.ok != 0 && r.density.size() == mesh.triangles.size();
  r.iterations = h.iterations;
  r.relaxed = h.relaxed;
  r.assembly = h.assembly;
  r.solve = h.solve;
  r.residual = h.residual;
  r.capacitance = h.capacitance;
  r.exact_residual = h.exact_residual;
  std::memcpy(r.solver, h.solver, sizeof r.solver);
  std::memcpy(r.error, h.error, sizeof r.error);
  r.peak_kb = usage.ru_maxrss;
  // CPU of the child up to the end of compute_charge (the exact residual excluded); the
  // wait4 figure covers the whole child.
  r.cpu = exact ? h.cpu : cpu_seconds(usage);
  return r;
}

std::vector<double> ellipsoid_exact(const TriangleMesh& m, double a, double b, double c) {
  const std::size_t n = m.triangles.size();
  std::vector<double> exact(n), area(n);
  double total = 0.0, charge = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const auto& t = m.triangles[j];
    const auto& p = m.vertices[t[0]];
    const auto& q = m.vertices[t[1]];
    const auto& s = m.vertices[t[2]];
    const double x = (p[0] + q[0] + s[0]) / 3, y = (p[1] + q[1] + s[1]) / 3,
                 z = (p[2] + q[2] + s[2]) / 3;
    exact[j] =
        1.0 / std::sqrt(x * x / std::pow(a, 4) + y * y / std::pow(b, 4) + z * z / std::pow(c, 4));
    const double u[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    const double v[3] = {s[0] - p[0], s[1] - p[1], s[2] - p[2]};
    area[j] = 0.5 * std::sqrt(std::pow(u[1] * v[2] - u[2] * v[1], 2) +
                              std::pow(u[2] * v[0] - u[0] * v[2], 2) +
                              std::pow(u[0] * v[1] - u[1] * v[0], 2));
    total += area[j];
    charge += area[j] * exact[j];
  }
  for (auto& e : exact) e *= total / charge;
  return exact;
}

/// Max and mean of |u - v| / |v| (pointwise) or, with `absolute`, of |u - v| (the densities
/// are relative: their area-weighted mean is 1, so this is the error in mean-density units).
std::pair<double, double> rel_error(const std::vector<double>& u, const std::vector<double>& v,
                                    bool absolute = false) {
  double worst = 0.0, mean = 0.0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const double e = absolute ? std::abs(u[i] - v[i]) : std::abs(u[i] / v[i] - 1.0);
    worst = std::max(worst, e);
    mean += e / static_cast<double>(u.size());
  }
  return {worst, mean};
}

std::string pct(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g %%", 100.0 * v);
  return b;
}

double exact_residual(const TriangleMesh& m, const std::vector<double>& density,
                      double capacitance) {
  namespace cd = preprocess::charge_detail;
  const cd::PanelSet panels = cd::make_panels(m.vertices, m.triangles, "");
  const cd::ClusterTree tree = cd::build_cluster_tree(panels, 32);
  const cd::NearField near = cd::build_near_field(panels, tree);
  double total = 0.0;
  for (const double a : panels.area) total += a;
  std::vector<double> y(density.size()), b(density.size(), 1.0);
  for (std::size_t j = 0; j < y.size(); ++j) y[j] = density[j] * capacitance / total;
  return cd::exact_residual(panels, near, b, y);
}

/// Wall and process CPU seconds since construction.
struct StageClock {
  std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
  double cpu = process_cpu();
  static double process_cpu() {
    timespec t{};
    ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  }
  std::string lap() {
    const auto now = std::chrono::steady_clock::now();
    const double c = process_cpu();
    char b[64];
    std::snprintf(b, sizeof b, "%.3f / %.3f", std::chrono::duration<double>(now - wall).count(),
                  c - cpu);
    wall = now;
    cpu = c;
    return b;
  }
};

/// `--stages`: wall / CPU seconds of compute_charge's internal stages for the fast solver
/// with the two-level preconditioner (set cap and K = min(2048, N / 64) as compute_charge
/// chooses them), in this process (no fork afterwards).
void print_stages(const std::string& name, const TriangleMesh& mesh, int order, double theta,
                  int schwarz_set) {
  namespace cd = preprocess::charge_detail;
  StageClock clock;
  const cd::PanelSet panels = cd::make_panels(mesh.vertices, mesh.triangles, "");
  const cd::ClusterTree tree = cd::build_cluster_tree(panels, ChargeOptions{}.leaf_size);
  const std::string t_tree = clock.lap();
  const cd::NearField near = cd::build_near_field(panels, tree);
  const std::string t_near = clock.lap();
  const std::size_t n = panels.size();
  const cd::TwoLevelSchwarz pre(panels, tree, near, cd::schwarz_set_for(n, schwarz_set),
                                std::min<std::size_t>(2048, n / 64));
  const std::string t_pre = clock.lap();
  const cd::TreecodeOperator op(panels, tree, near, theta, order);
  const std::string t_fmm = clock.lap();
  std::vector<double> x(n, 1.0), y(n);
  op.apply(x.data(), y.data());
  const std::string t_apply = clock.lap();
  pre.apply(x.data(), y.data());
  const std::string t_pre_apply = clock.lap();
  std::printf("| %s | %zu | %s | %s | %s | %s | %s | %s |\n", name.c_str(), n, t_tree.c_str(),
              t_near.c_str(), t_pre.c_str(), t_fmm.c_str(), t_apply.c_str(), t_pre_apply.c_str());
  std::fflush(stdout);
}

/// A `--solvers` entry, "name[/preconditioner][@tolerance|@auto][:order[:theta]]", as the
/// options of its timed runs (the other options from the command line). Throws
/// ToolError(kExitUsage) naming the entry when it does not parse.
struct SolverRun {
  std::string spec;
  ChargeOptions options;
};

SolverRun parse_solver(const std::string& spec, double tolerance, int order, double theta,
                       int leaf_size, int schwarz_set, bool exact_products) {
  auto bad = [&](const std::string& why) {
    return ToolError(kExitUsage, "", "--solvers " + spec + ": " + why);
  };
  // All of `text` as a finite number (std::stod alone takes a prefix: "1e-8x").
  auto number = [&](const std::string& text, const char* what) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v))
      throw bad(std::string("bad ") + what + " '" + text + "'");
    return v;
  };
  const std::size_t colon = spec.find(':');
  const std::string main_spec = spec.substr(0, colon);
  const std::size_t at = main_spec.find('@');
  const std::string head = main_spec.substr(0, at);
  const std::size_t slash = head.find('/');
  const std::string name = head.substr(0, slash);
  const std::string pre = slash == std::string::npos ? "" : head.substr(slash + 1);
  SolverRun run{spec, ChargeOptions{}};
  ChargeOptions& o = run.options;
  if (!preprocess::parse_name(name, o.solver)) throw bad("unknown solver '" + name + "'");
  if (!pre.empty() && !preprocess::parse_name(pre, o.preconditioner))
    throw bad("unknown preconditioner '" + pre + "'");
  // "@auto" leaves the tolerance to compute_charge (0).
  o.tolerance = tolerance;
  if (at != std::string::npos) {
    const std::string t = main_spec.substr(at + 1);
    o.tolerance = t == "auto" ? 0.0 : number(t, "tolerance");
  }
  o.fast_order = order;
  o.fast_theta = theta;
  o.leaf_size = leaf_size;
  o.schwarz_set = schwarz_set;
  o.relaxed_products = !exact_products;
  if (colon != std::string::npos) {
    const std::string rest = spec.substr(colon + 1);
    const std::size_t colon2 = rest.find(':');
    const double fmm_order = number(rest.substr(0, colon2), "order");
    if (fmm_order != std::floor(fmm_order) || std::fabs(fmm_order) > 1e6)
      throw bad("the order must be a whole number");
    o.fast_order = static_cast<int>(fmm_order);
    if (colon2 != std::string::npos) o.fast_theta = number(rest.substr(colon2 + 1), "theta");
  }
  // The library's ranges (option_ranges.hpp), checked here rather than in each child.
  try {
    preprocess::check_option(preprocess::option_ranges::kTolerance, o.tolerance);
    preprocess::check_option(preprocess::option_ranges::kTheta, o.fast_theta);
    preprocess::check_option(preprocess::option_ranges::kOrder, o.fast_order);
  } catch (const std::invalid_argument& e) {
    throw bad(e.what());
  }
  return run;
}

struct Args {
  std::string mesh_dir = TETSEG_BENCH_MESH_DIR;
  std::string real = "elephant.off";
  bool real_given = false;  // --real or --mesh-dir on the command line: the mesh must read
  std::vector<std::string> sizes = {"1k", "5k", "20k", "100k"};
  std::vector<std::string> solvers = {"direct", "gmres", "fast", "fast@1e-8"};
  double tolerance = 1e-6;
  bool reference = true;
  int repeat = 1;
  std::size_t exact_max = 25000;
  int order = -1;
  double theta = 0.0;
  int schwarz_set = 0;
  bool exact_products = false;
  int leaf_size = ChargeOptions{}.leaf_size;
  bool stages = false;
};

int run(const Args& a) {
  // Every --solvers entry parses before any work starts.
  std::vector<SolverRun> runs;
  for (const std::string& spec : a.solvers)
    runs.push_back(parse_solver(spec, a.tolerance, a.order, a.theta, a.leaf_size, a.schwarz_set,
                                a.exact_products));

  struct Mesh {
    std::string name, size;
    TriangleMesh mesh;
    bool analytic;
  };
  std::vector<Mesh> meshes;
  // 20 k^2 triangles: 980, 5120, 20,480, 100,820, 81,920, 327,680, 1,310,720.
  const int ks[] = {7, 16, 32, 71, 64, 128, 256};
  const char* names[] = {"1k", "5k", "20k", "100k", "82k", "327k", "1.3M"};
  // The real mesh ("none": ellipsoids only): the tools' reader (the file's vertices in their
  // order). A mesh named on the command line must read; the default one may be missing (the
  // demo meshes not unpacked).
  const std::string real_path = a.mesh_dir + "/" + a.real;
  TriangleMesh base;
  bool have_real = false;
  if (a.real == "none") {
    // ellipsoids only
  } else if (a.real_given || std::ifstream(real_path).good()) {
    try {
      base = preprocess::read_triangle_mesh_keeping_vertices(real_path);
    } catch (const preprocess::InputError& e) {
      throw ToolError(kExitBadInput, e.file(), e.what());
    }
    have_real = true;
  } else {
    std::fprintf(stderr, "%s: no real mesh (%s missing); ellipsoids only\n", kTool,
                 real_path.c_str());
  }
  for (int s = 0; s < 7; ++s) {
    if (std::find(a.sizes.begin(), a.sizes.end(), names[s]) == a.sizes.end()) continue;
    meshes.push_back(
        {"ellipsoid 1:0.6:0.3", names[s], test::ellipsoid(ks[s], 1.0, 0.6, 0.3), true});
    if (have_real) {
      TriangleMesh m = base;
      // elephant: 5558 -> 22232 -> 88928; the 1k class uses the mesh as given.
      const std::size_t targets[] = {0, 5000, 20000, 80000, 80000, 320000, 1280000};
      const std::size_t target = targets[s];
      while (m.triangles.size() < target) m = test::subdivide(m);
      if (s == 0 && m.triangles.size() > 2000) continue;  // no ~1k version of this mesh
      meshes.push_back({a.real, names[s], m, false});
    }
  }

  if (a.stages) {
    std::printf(
        "| mesh | N | panels + tree | near field | two-level setup | FMM lists | one FMM product "
        "| one preconditioner application |\n|---|---|---|---|---|---|---|---|\n");
    for (const Mesh& m : meshes) {
      print_stages(m.name, m.mesh, a.order >= 0 ? a.order : 8, a.theta > 0.0 ? a.theta : 0.45,
                   a.schwarz_set);
    }
    return kExitOk;
  }
  std::printf(
      "| mesh | N | solver | assembly s | solve s | total s | CPU s | iterations | residual | "
      "exact residual | peak RSS MB | error vs analytic, max / mean | vs reference, max / mean | "
      "vs reference, max abs | reference "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Mesh& m : meshes) {
    const std::size_t n = m.mesh.triangles.size();
    std::vector<double> exact;
    if (m.analytic) exact = ellipsoid_exact(m.mesh, 1.0, 0.6, 0.3);
    // Best reference available: dense LU up to 5k, GMRES at 1e-10 on the stored matrix up to
    // 25k, else the FMM at theta 0.35 / order 10 to 1e-10 (operator error ~ 0.35^11, about
    // 1/500 of the timed runs' theta 0.5 / order 8).
    std::vector<double> ref;
    std::string ref_name = "-";
    if (a.reference) {
      ChargeOptions o;
      o.tolerance = 1e-10;
      o.max_iterations = 2000;
      if (n <= 6000) {
        o.solver = ChargeSolver::kDirect;
        ref_name = "direct LU";
      } else if (n <= 25000) {
        o.solver = ChargeSolver::kGmres;
        ref_name = "gmres 1e-10";
      } else {
        o.solver = ChargeSolver::kFast;
        o.fast_theta = 0.35;
        o.fast_order = 10;
        ref_name = "fast theta 0.35 order 10, 1e-10";
      }
      std::fprintf(stderr, "%s: %s %zu reference (%s)\n", kTool, m.name.c_str(), n,
                   ref_name.c_str());
      const CaseResult r = run_case(m.mesh, o);
      if (r.ok) {
        ref = r.density;
      } else {
        ref_name = std::string("failed: ") + r.error;
      }
    }
    for (const SolverRun& run : runs) {
      const ChargeOptions& o = run.options;
      if (o.solver == ChargeSolver::kDirect && n > 6000) continue;
      if (o.solver == ChargeSolver::kGmres && n > 25000) continue;
      std::fprintf(stderr, "%s: %s %zu %s\n", kTool, m.name.c_str(), n, run.spec.c_str());
      const bool with_exact = n <= a.exact_max;
      CaseResult r = run_case(m.mesh, o, with_exact);
      for (int k = 1; k < a.repeat && r.ok; ++k) {
        CaseResult again = run_case(m.mesh, o, with_exact);
        if (again.ok && again.assembly + again.solve < r.assembly + r.solve) r = std::move(again);
      }
      if (!r.ok) {
        std::printf("| %s | %zu | %s | failed: %s |\n", m.name.c_str(), n, run.spec.c_str(),
                    r.error);
        continue;
      }
      std::string analytic = "-", vs_ref = "-", vs_ref_abs = "-", exact_res = "-";
      if (r.exact_residual >= 0.0) {
        char b[32];
        std::snprintf(b, sizeof b, "%.1e", r.exact_residual);
        exact_res = b;
      }
      if (!exact.empty()) {
        const auto e = rel_error(r.density, exact);
        analytic = pct(e.first) + " / " + pct(e.second);
      }
      if (!ref.empty()) {
        const auto e = rel_error(r.density, ref);
        vs_ref = pct(e.first) + " / " + pct(e.second);
        vs_ref_abs = pct(rel_error(r.density, ref, true).first);
      }
      // Iterations, and how many of them took relaxed products.
      std::string iterations = std::to_string(r.iterations);
      if (r.relaxed > 0) iterations += " (" + std::to_string(r.relaxed) + " relaxed)";
      std::printf(
          "| %s | %zu | %s | %.3f | %.3f | %.3f | %.2f | %s | %.1e | %s | %.0f | %s | %s | %s | %s "
          "|\n",
          m.name.c_str(), n, run.spec.c_str(), r.assembly, r.solve, r.assembly + r.solve, r.cpu,
          iterations.c_str(), r.residual, exact_res.c_str(),
          static_cast<double>(r.peak_kb) / 1024.0, analytic.c_str(), vs_ref.c_str(),
          vs_ref_abs.c_str(), ref_name.c_str());
      std::fflush(stdout);
    }
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tetseg-bench-charge " TETSEG_VERSION
               ": run time, iterations, peak memory and error of each charge-density solver on "
               "ellipsoids and a subdivided CGAL demo mesh (docs/benchmarks.md)",
               "tetseg-bench-charge"};
  app.set_version_flag("--version", "tetseg-bench-charge " TETSEG_VERSION);
  Args a;
  app.add_option("--mesh-dir", a.mesh_dir, "Directory with the CGAL demo meshes");
  app.add_option("--real", a.real,
                 "Real mesh (OFF, PLY, OBJ) in --mesh-dir subdivided to the sizes; none: "
                 "ellipsoids only");
  app.add_option("--sizes", a.sizes,
                 "Any of 1k 5k 20k 100k 82k 327k 1.3M (ellipsoids of 20 k^2 triangles)")
      ->check(CLI::IsMember({"1k", "5k", "20k", "100k", "82k", "327k", "1.3M"}));
  app.add_option("--solvers", a.solvers,
                 "Any of direct gmres fast auto, optionally name/preconditioner (jacobi, block, "
                 "near, two), @tolerance (name@auto: automatic) and :order[:theta] of the FMM");
  app.add_option("--order", a.order, "FMM order of the timed fast runs (default automatic)");
  app.add_option("--leaf-size", a.leaf_size, "Cluster-tree leaf size of the timed runs")
      ->check(CLI::PositiveNumber);
  app.add_option("--schwarz-set", a.schwarz_set,
                 "Schwarz set cap of the timed runs and --stages (0: automatic)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--exact-products", a.exact_products,
               "Timed fast runs: no relaxed (cheaper) GMRES products");
  app.add_option("--theta", a.theta, "FMM opening parameter of the timed fast runs (0: automatic)");
  app.add_option("--exact-residual-max", a.exact_max,
                 "Largest N for the residual against the exact matrix (O(N^2) product)");
  app.add_option("--tolerance", a.tolerance, "Relative residual for the timed runs")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-reference{false}", a.reference, "Skip the reference solves");
  app.add_flag("--stages", a.stages,
               "Instead of the solver table: wall / CPU s of the fast solver's stages (two-level "
               "preconditioner; --order, default 8, and --theta, default 0.45)");
  app.add_option("--repeat", a.repeat, "Runs per timed case; the row shows the fastest (wall)")
      ->check(CLI::PositiveNumber);
  return run_tool(kTool, app, argc, argv, [&] {
    a.real_given = app.count("--real") + app.count("--mesh-dir") > 0;
    return run(a);
  });
}
