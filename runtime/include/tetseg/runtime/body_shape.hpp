#pragma once
/// \file
/// The immutable surface topology of one body, built once and shared (read-only, by any
/// number of colliders, scene bodies and threads): surface vertices, unique edges and the
/// vertex/edge -> triangle adjacency, plus the asset's clusters for a tet body.

#include <cstddef>
#include <cstdint>
#include <memory>

#include "tetseg/runtime/asset.hpp"

namespace tetseg {

class BodyShape {
 public:
  /// Topology of an asset's surface (a tet body: clusters, detector nodes and their BVHs,
  /// usable by every collider mode). `asset` must outlive the shape and stay unchanged.
  /// Null when out of memory.
  static std::shared_ptr<const BodyShape> from_asset(const Asset& asset) noexcept;
  /// Topology of a triangle mesh with no asset (a surface-only body: obstacles, cloth, shells,
  /// triangle soups; overlap culling only, no `kRvbc`). `triangles`: `triangle_count` * 3 node
  /// ids, each < `node_count`; triangles with a repeated node are rejected. Copied. Null when
  /// out of memory or the ids are invalid.
  static std::shared_ptr<const BodyShape> from_triangles(const std::uint32_t* triangles,
                                                         std::size_t triangle_count,
                                                         std::uint32_t node_count) noexcept;

  std::uint32_t node_count() const noexcept;
  std::uint32_t triangle_count() const noexcept;
  /// True for a shape from an asset (radial-view culling available).
  bool has_clusters() const noexcept;

  struct Data;  ///< private layout (runtime/src/body_shape_data.hpp)
  const Data& data() const noexcept { return *m_data; }

  ~BodyShape();
  BodyShape(const BodyShape&) = delete;
  BodyShape& operator=(const BodyShape&) = delete;

 private:
  BodyShape() noexcept;
  std::unique_ptr<Data> m_data;
};

}  // namespace tetseg
