#pragma once
// Private: the soup repairs of `--repair fix` (repair.cpp, CGAL polygon-soup processing).

#include <vector>

#include "tetseg/preprocess/meshing.hpp"

namespace tetseg::preprocess::detail {

/// Repairs that keep the shape, in this order: triangles with a repeated corner removed,
/// duplicate triangles (same three vertices, either orientation) merged, orientation made
/// consistent (CGAL orient_polygon_soup: triangles flipped, non-manifold vertices
/// duplicated), unused vertices dropped. Returns the repairs made (kind, count; kinds with a
/// zero count are left out). Vertex ids are renumbered in order of first use.
std::vector<RepairCount> repair_soup(TriangleMesh& mesh);

}  // namespace tetseg::preprocess::detail
