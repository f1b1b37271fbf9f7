#pragma once
// Private: CGAL Mesh_3 driven on a closed surface (meshing.cpp: sizes, vertex budget,
// sharp-edge protection, time bound, retries), for tetrahedralize.cpp, which chooses the
// surface (--repair fix / wrap / slab / auto).

#include <string>
#include <vector>

#include "tetseg/preprocess/meshing.hpp"

namespace tetseg::preprocess::detail {

class Watchdog;

/// The diagonal of the points' axis-aligned bounding box (0 without points).
double bounding_box_diagonal(const std::vector<Vec3>& points);

/// Validation of `source` (pinch points and several closed components accepted: the domain
/// only needs inside/outside queries, and the output is validated strictly), then Mesh_3 with
/// the retries of tetrahedralize; after --repair fix, a refusal of the surface names what is
/// left with a pointer to wrap. Each Mesh_3 run is bounded by `bound_seconds` when > 0 (and
/// always by the time limit of `watchdog`). With `max_distance` > 0 (absolute), meshing is
/// repeated at smaller sizes while the meshed boundary lies further than that from `source`
/// (meshing.cpp, kMaxDeviationRetries: a bounded number of retries, each bounded in vertices,
/// none expected to pass kMaxRetryVertices), and the nearest mesh is returned;
/// notes.deviation_retries and notes.deviation_retry_sizes say what was done. Throws InputError,
/// TimeLimitExceeded.
TetMesh validate_and_mesh(const TriangleMesh& source, const MeshingOptions& meshing,
                          const std::string& file, TetrahedralizeNotes& notes, Watchdog& watchdog,
                          double bound_seconds = 0.0, double max_distance = 0.0);

}  // namespace tetseg::preprocess::detail
