#pragma once
// Internal: cluster tree over triangle centroids, the analytic near field (sparse), and the
// treecode matrix-free operator of the collocation matrix (docs/charge.md, "fast").

#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "charge_potential.hpp"

namespace tetseg::preprocess::charge_detail {

/// A node of the binary cluster tree. Members of a node are order[begin, end).
struct Cluster {
  Vec3 center{};        ///< bounding-box centre
  double radius = 0.0;  ///< max distance of a member centroid from `center`
  Vec3 box_min{}, box_max{};
  double max_diameter = 0.0;  ///< longest triangle edge among the members
  std::uint32_t begin = 0, end = 0;
  std::int32_t left = -1, right = -1;  ///< children, -1 for a leaf
};

struct ClusterTree {
  std::vector<Cluster> nodes;        ///< nodes[0] is the root
  std::vector<std::uint32_t> order;  ///< triangle ids in tree order
  std::vector<std::int32_t> leaves;  ///< node ids of the leaves, left to right
};

/// Median splits along the longest box axis until a node has at most `leaf_size` members.
ClusterTree build_cluster_tree(const PanelSet& panels, int leaf_size);

/// std::allocator whose value-initialisation leaves scalars uninitialised: vectors that are
/// filled in parallel right after resize() skip a serial zero-fill (at 5k the near field's
/// 6 MB cost 3 ms of one thread, mostly first-touch page faults).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() = default;
  template <class U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using UninitializedVector = std::vector<T, UninitializedAllocator<T>>;

/// The near field of the collocation matrix in CSR form: for row i, the columns j with
/// |c_i - c_j| <= kNearFactor * diameter_j (always including j = i) and the entry M_ij
/// (closed form, or the six-point quadrature beyond kQuadratureFactor diameters: the rule of
/// matrix_entry), plus `correction` = M_ij minus the point-charge entry A_j / r_ij (M_ii for
/// j = i). A row's columns are in tree order, not sorted. compute_charge's fast path frees
/// `value` once the preconditioner is built.
struct NearField {
  std::vector<std::size_t> row_start;  ///< size n + 1
  UninitializedVector<std::uint32_t> column;
  UninitializedVector<double> value;
  UninitializedVector<double> correction;
  std::vector<double> diagonal;  ///< M_ii
};

NearField build_near_field(const PanelSet& panels, const ClusterTree& tree);

/// Panel centroids and areas in tree order (structure of arrays): the layout the direct-sum
/// kernels read (charge_fmm_kernels.hpp).
struct TreeOrderedPanels {
  std::vector<double> x, y, z, area;
};
TreeOrderedPanels in_tree_order(const PanelSet& panels, const ClusterTree& tree);

/// One step of the Duan-Krasny recurrence for the Taylor coefficients of 1 / |R + w|: slot k
/// from its predecessors k - e_i (m1) and k - 2 e_i (m2), or the zero slot when missing.
struct TaylorRecurrence {
  std::uint32_t m1[3], m2[3];
  double alpha, beta;  ///< -(2|k| - 1) / |k|, -(|k| - 1) / |k|
};

/// y = M x with M's far part (point charges) approximated by a Cartesian Taylor fast
/// multipole method on the binary cluster tree: moments up to total order `order` (leaves
/// from their members, parents by exact shifts), a dual-tree traversal that turns every pair
/// of clusters with (r_target + r_source) < theta * distance into a multipole-to-local
/// translation truncated at total order `order` (error ~ theta^(order + 1)), exact local
/// shifts down the tree, and direct sums between the remaining leaf pairs. The near field is
/// exact. Interaction lists are built once in the constructor; apply() uses internal scratch
/// buffers, so one caller at a time.
class TreecodeOperator {
 public:
  TreecodeOperator(const PanelSet& panels, const ClusterTree& tree, const NearField& near,
                   double theta, int order);
  std::size_t size() const { return m_n; }
  void apply(const double* x, double* y) const;
  /// Cost indicators: multipole-to-local translations, and direct source points per target.
  std::size_t m2l_count() const { return m_far.size(); }
  double direct_per_target() const { return m_direct_per_target; }

 private:
  void shift_terms(std::vector<std::array<int, 3>>& out, bool upward) const;
  std::size_t m_n;
  int m_order;
  const ClusterTree& m_tree;
  const NearField& m_near;
  TreeOrderedPanels m_sources;
  std::vector<std::int32_t> m_parent;        ///< per node, -1 for the root
  std::vector<std::int32_t> m_leaf_of_node;  ///< leaf index or -1
  std::vector<std::size_t> m_far_start;      ///< per node (CSR): M2L sources
  std::vector<std::int32_t> m_far;
  std::vector<std::size_t> m_direct_start;  ///< per leaf (CSR): source leaves (node ids)
  std::vector<std::int32_t> m_direct;
  double m_direct_per_target = 0.0;
  // Multi-indices k with |k| <= order, graded order.
  std::vector<std::array<int, 3>> m_index;
  std::vector<std::array<int, 3>> m_minus1;  ///< index of k - e_i, or -1
  std::vector<std::array<int, 3>> m_minus2;  ///< index of k - 2 e_i, or -1
  std::vector<TaylorRecurrence> m_recurrence;
  std::vector<std::uint32_t> m_mono_from;  ///< per k > 0: the index of k - e_axis
  std::vector<std::uint8_t> m_mono_axis;   ///< per k > 0: the first axis with k_axis > 0
  struct Term {
    int a, b, c;
    double coef;
  };
  std::vector<Term> m_m2l;               ///< L_a += coef * D_c(R) * M_b with c = a + b, sorted by a
  std::vector<std::size_t> m_m2l_start;  ///< first term of each a
  // The same M2L sum in scaled form, without per-term coefficients:
  // L_a = (1 / a!) sum_b (c! D_c) ((-1)^|b| M_b / b!), c = a + b, k! = k_x! k_y! k_z!.
  std::vector<std::uint16_t> m_m2l_b, m_m2l_c;  ///< b and c of each m_m2l term
  std::vector<double> m_fact, m_inv_fact;       ///< k!, 1 / k!
  std::vector<double> m_moment_scale;           ///< (-1)^|k| / k!
  std::vector<Term> m_m2m;  ///< M_a(parent) += coef * d^c * M_b(child), c = a - b
  std::vector<Term> m_l2l;  ///< L_a(child) += coef * d^c * L_b(parent), c = b - a
  std::vector<std::size_t> m_m2m_start, m_l2l_start;  ///< first term of each a
  std::vector<std::int32_t> m_top_nodes;              ///< nodes above the subtrees, parents first
  std::vector<std::size_t> m_subtree_start;           ///< per subtree (CSR) into m_subtree_nodes
  std::vector<std::int32_t> m_subtree_nodes;          ///< each subtree's nodes in post-order
  mutable UninitializedVector<double> m_charge;
  mutable UninitializedVector<double> m_moments;  ///< nodes x index count
  mutable UninitializedVector<double> m_local;    ///< nodes x index count
  mutable UninitializedVector<double> m_scaled;   ///< nodes x index count: M_k (-1)^|k| / k!
};

}  // namespace tetseg::preprocess::charge_detail
