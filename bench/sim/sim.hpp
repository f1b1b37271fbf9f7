#pragma once
/// \file
/// `tetseg-sim`'s engine: a deterministic XPBD soft body (edge-length and tet-volume
/// constraints, Macklin et al. "small steps"), gravity, a ground plane with Coulomb friction,
/// and self-contact made safe with the runtime's own continuous queries (docs/simulation.md).
///
/// Self-contact rule: every substep `x_prev -> x_new` is checked with a `tetseg::Collider` on
/// the object's asset. While it reports contacts, the nodes of every reported contact are
/// frozen for the substep (position back to `x_prev`, velocity zero: a rigid impact zone with
/// zero motion) and the step is queried again. A contact needs a moving node, so each round
/// freezes at least one more node and the loop ends; the final substep is collision-free, so
/// from an intersection-free start every state stays intersection-free.
///
/// Deterministic: fixed constraint order, no threads, no randomness; two runs with the same
/// inputs produce bit-identical positions. Not thread-safe (one `SoftBody` per thread).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"

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
  bool self_contact = true;  ///< false: no self-contact handling (for tests and comparisons)
};

/// Totals over a run.
struct SimCounters {
  std::uint64_t substeps = 0;
  std::uint64_t substeps_with_contact = 0;  ///< substeps whose first query found contacts
  std::uint64_t contacts_resolved = 0;      ///< contacts reported by all query rounds
  std::uint64_t query_rounds = 0;           ///< collider queries (>= substeps)
  std::uint64_t nodes_frozen = 0;           ///< node freezes by the self-contact response
  std::uint64_t ground_contacts = 0;        ///< node-substeps clamped to the ground
  std::uint32_t max_rounds = 0;             ///< most query rounds in one substep
};

/// One soft body. Node ids are the tet mesh's and the asset's (they must agree).
class SoftBody {
 public:
  /// `mesh`: positively oriented tets; `asset`: built from the same mesh (same node count),
  /// must outlive the body. `start`: initial positions (node_count * 3), e.g. the mesh moved
  /// above the ground. Throws preprocess::InputError (file = `what`) when the mesh and asset
  /// disagree, a tet is degenerate, options are out of range, or the start surface
  /// self-intersects (checked with `Collider::check_rest_intersection`).
  SoftBody(const preprocess::TetMesh& mesh, const tetseg::Asset& asset,
           const std::vector<double>& start, const SimOptions& options, const std::string& what);

  /// Advances one frame (`options.substeps` substeps). Throws std::runtime_error if the
  /// collider fails (never expected).
  void advance_frame();
  /// Current positions, node_count * 3 doubles.
  const std::vector<double>& positions() const noexcept { return m_x; }
  const SimCounters& counters() const noexcept { return m_counters; }

 private:
  void substep(double h);
  void solve_constraints(double h);
  void apply_ground();
  void resolve_self_contact();

  SimOptions m_opt;
  std::size_t m_node_count = 0;
  std::vector<std::array<std::uint32_t, 2>> m_edges;
  std::vector<double> m_edge_rest;
  std::vector<preprocess::Tet> m_tets;
  std::vector<double> m_tet_rest;  // rest volumes
  std::vector<double> m_inv_mass;
  std::vector<double> m_x, m_x_prev, m_v;
  tetseg::Collider m_collider;
  std::vector<tetseg::Contact> m_contacts;
  std::vector<std::uint8_t> m_frozen;
  SimCounters m_counters;
};

/// Start positions: `nodes` rotated by `tilt_x` degrees about the x axis, then `tilt_y`
/// degrees about the y axis (both about the mesh's centroid), then moved so that the lowest
/// point along `up_axis` is `drop_height` above `ground`. Pure function.
std::vector<double> place_above_ground(const std::vector<preprocess::Vec3>& nodes, int up_axis,
                                       double ground, double drop_height, double tilt_x,
                                       double tilt_y);

}  // namespace tetseg::tools
