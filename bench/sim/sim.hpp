#pragma once
/// \file
/// `tetseg-sim`'s engine: deterministic XPBD soft bodies (edge-length and tet-volume
/// constraints, Macklin et al. "small steps"), gravity, a ground plane with Coulomb friction,
/// still obstacles, and contact made safe with the runtime's own continuous scene queries
/// (docs/simulation.md).
///
/// Contact rule: every substep `x_prev -> x_new` of all bodies is checked with a
/// `tetseg::Scene` (the bodies' assets, still obstacles as surface-only bodies). While it
/// reports contacts, the moving nodes of every reported contact are
/// frozen for the substep (position back to `x_prev`, velocity zero: a rigid impact zone with
/// zero motion) and the step is queried again. A contact needs a moving node, so each round
/// freezes at least one more node and the loop ends; the final substep is collision-free, so
/// from an intersection-free start every state stays intersection-free.
///
/// Deterministic: fixed constraint order, no threads, no randomness; two runs with the same
/// inputs produce bit-identical positions. Not thread-safe (one `Simulation` per thread).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/scene.hpp"

namespace tetseg::tools {

struct SimOptions {
  double frame_dt = 1.0 / 60.0;   ///< seconds between written frames, > 0
  std::uint32_t substeps = 4;     ///< XPBD substeps per frame (each collision-checked), >= 1
  std::uint32_t iterations = 1;   ///< constraint sweeps per substep, >= 1
  double gravity = 9.81;          ///< m/s^2 along -up
  int up_axis = 2;                ///< 0 = x, 1 = y, 2 = z
  double ground = 0.0;            ///< ground plane height along the up axis (length units)
  double friction = 0.5;          ///< Coulomb coefficient on the ground, >= 0
  double density = 1000.0;        ///< kg per cubic length unit (only mass ratios matter)
  double edge_compliance = 1e-4;  ///< XPBD compliance of edge-length constraints (>= 0)
  double volume_compliance = 0;   ///< XPBD compliance of tet-volume constraints (>= 0)
  double damping = 0.5;           ///< linear velocity damping per second, >= 0
  tetseg::ColliderMode collider_mode = tetseg::ColliderMode::kRvbc;
  std::size_t contact_capacity = 1 << 14;  ///< contacts read per query round
  bool self_contact = true;  ///< false: no contact handling at all (for tests and comparisons)
  /// Twisting by the ends: when non-zero, the nodes of every soft body within
  /// `twist_ends` x its length of either end along `twist_axis` (at the start) are kinematic
  /// (no gravity, no constraint moves them): they turn about the axis line through the body's
  /// start centroid, the two ends in opposite directions, each at twist_rate / 2 degrees per
  /// second (so the ends turn twist_rate against each other).
  double twist_rate = 0;
  int twist_axis = 0;        ///< 0 = x, 1 = y, 2 = z
  double twist_ends = 0.05;  ///< share of the body's length held at each end, in (0, 0.5)
};

/// Totals over a run.
struct SimCounters {
  std::uint64_t substeps = 0;
  std::uint64_t substeps_with_contact = 0;  ///< substeps whose first query found contacts
  std::uint64_t contacts_resolved = 0;      ///< contacts reported by all query rounds
  std::uint64_t body_contacts = 0;          ///< of those, contacts between two bodies
  std::uint64_t query_rounds = 0;           ///< scene queries (>= substeps)
  std::uint64_t nodes_frozen = 0;           ///< node freezes by the contact response
  std::uint64_t ground_contacts = 0;        ///< node-substeps clamped to the ground
  std::uint32_t max_rounds = 0;             ///< most query rounds in one substep
  std::uint64_t queries_recorded = 0;       ///< query steps appended by `record_queries`
};

/// One soft body's dynamics (no contact handling: `Simulation` does that for all bodies).
/// Node ids are the tet mesh's.
class SoftBody {
 public:
  /// `mesh`: positively oriented tets. `start`: initial positions (node_count * 3), e.g. the
  /// mesh moved above the ground. Throws preprocess::InputError (file = `what`) when a tet is
  /// degenerate, options are out of range or the start has the wrong size.
  SoftBody(const preprocess::TetMesh& mesh, const std::vector<double>& start,
           const SimOptions& options, const std::string& what);

  /// Substep, first part: `x_prev = x`, gravity and damping, constraint sweeps, ground.
  void predict(double h, SimCounters& counters);
  /// Substep, last part: velocities from the accepted positions.
  void finish(double h);
  /// Puts node `n` back to `x_prev` (zero velocity this substep); false when it did not move.
  bool freeze(std::uint32_t n);

  std::size_t node_count() const noexcept { return m_node_count; }
  /// Current positions and those at the start of the substep, node_count * 3 doubles.
  const std::vector<double>& positions() const noexcept { return m_x; }
  const std::vector<double>& previous() const noexcept { return m_x_prev; }

 private:
  void solve_constraints(double h);
  void apply_ground(SimCounters& counters);
  void hold_twisted_ends();

  struct HeldNode {
    std::uint32_t node;
    double sign;  // +1 at the far end, -1 at the near end
    double start[3];
  };
  std::vector<HeldNode> m_held;  // twist: kinematic end nodes
  double m_center[3] = {0, 0, 0};
  double m_time = 0;

  SimOptions m_opt;
  std::size_t m_node_count = 0;
  std::vector<std::array<std::uint32_t, 2>> m_edges;
  std::vector<double> m_edge_rest;
  std::vector<preprocess::Tet> m_tets;
  std::vector<double> m_tet_rest;  // rest volumes
  std::vector<double> m_inv_mass;
  std::vector<double> m_x, m_x_prev, m_v;
};

/// A still obstacle: a triangle mesh (surface only) that never moves.
struct Obstacle {
  std::vector<double> positions;  ///< node_count * 3
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// Several soft bodies and still obstacles in one `tetseg::Scene`. Contact rule: every substep
/// `x_prev -> x` of all bodies is queried over the whole scene (self-contact of each soft body,
/// every pair of bodies; obstacles have no self-collision and two obstacles are never tested).
/// While it reports contacts, the soft-body nodes of every reported contact are frozen (see
/// the file comment) and the scene is queried again; the accepted substep is collision-free.
/// Bodies are numbered in order of addition (soft bodies and obstacles alike), which is also
/// their order in `positions()`.
class Simulation {
 public:
  explicit Simulation(const SimOptions& options);
  ~Simulation();

  /// Adds a soft body. `asset` (built from `mesh`, same node count) must outlive the
  /// simulation. Throws preprocess::InputError (file = `what`) as `SoftBody`, or when the asset
  /// and mesh disagree.
  void add_body(const preprocess::TetMesh& mesh, const tetseg::Asset& asset,
                const std::vector<double>& start, const std::string& what);
  /// Adds a still obstacle. Throws InputError (file = `what`) on invalid triangles.
  void add_obstacle(Obstacle obstacle, const std::string& what);
  /// Checks the start state (no soft body touches itself, no two bodies touch); throws
  /// InputError naming the bodies' `what` otherwise. Call once, after adding every body.
  void check_start();

  /// Records the collision queries: from now on, every `every`-th substep whose first query
  /// finds a contact appends two frames to `out` (positions of all bodies, as
  /// `append_positions`): the substep's start and its predicted end, before the contact
  /// response. `out` (null: stop recording) must outlive the recording; `every` >= 1.
  void record_queries(std::vector<double>* out, std::uint32_t every);

  /// Advances one frame (`options.substeps` substeps). Throws std::runtime_error if the scene
  /// fails (never expected).
  void advance_frame();
  /// Positions of all bodies in order of addition (appended to `out`).
  void append_positions(std::vector<double>& out) const;
  std::size_t node_count() const noexcept;
  const SimCounters& counters() const noexcept { return m_counters; }

 private:
  struct Body;
  void substep(double h);
  void resolve_contacts();
  void set_positions();
  void append_starts(std::vector<double>& out) const;

  SimOptions m_opt;
  std::vector<double>* m_record = nullptr;
  std::uint32_t m_record_every = 1;
  std::vector<Body> m_bodies;
  tetseg::Scene m_scene;
  std::vector<tetseg::Contact> m_contacts;
  SimCounters m_counters;
};

/// Start positions: `nodes` rotated by `tilt_x` degrees about the x axis, then `tilt_y`
/// degrees about the y axis (both about the mesh's centroid), then moved so that the lowest
/// point along `up_axis` is `drop_height` above `ground`. Pure function.
std::vector<double> place_above_ground(const std::vector<preprocess::Vec3>& nodes, int up_axis,
                                       double ground, double drop_height, double tilt_x,
                                       double tilt_y);

}  // namespace tetseg::tools
