#pragma once
/// \file
/// Structured tet meshes built directly (no Mesh_3): grids of hexahedra, each split into six
/// tets, for the thin shapes of the IPC benchmark scenes (mats, plates, bars, tori) that
/// Mesh_3 cannot make one tet thick. What `tetseg generate mat|plate|bar|torus|tori` runs.

#include <functional>
#include <string>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// nx x ny x nz hexahedra, each split into six tets around its diagonal from corner (i, j, k)
/// to (i+1, j+1, k+1) (Kuhn), so neighbouring hexes share face diagonals and the mesh is
/// conforming. Node (i, j, k) sits at map(i, j, k) and has id (i * (ny + 1) + j) * (nz + 1) +
/// k. With `periodic_x` the layer i = nx is layer 0 again (nx >= 3; ids as above with nx
/// layers of nodes): a ring of hexes swept around an axis. Each tet is wound positively after
/// mapping (two nodes swapped when needed). Throws std::invalid_argument on a count < 1.
TetMesh hex_grid(int nx, int ny, int nz, const std::function<Vec3(int, int, int)>& map,
                 bool periodic_x = false);

/// The generated thin shapes, their sizes in hexes and metres-free units:
enum class StructuredShape {
  kMat,    ///< side 1 x 1, resolution x resolution hexes, `layers` hexes thick (default 1)
  kPlate,  ///< kMat with `layers` default 3
  kBar,    ///< length 1 along x, resolution hexes long, layers x layers hexes across (1)
  kTorus,  ///< major radius 1 about z, resolution hexes around, layers x layers across (1)
  kTori,   ///< two kTorus links interlocked (second about y, centred at x = 1); layers 3
};

/// Parameters of generate_structured; 0 = the shape's default.
struct StructuredOptions {
  int resolution = 0;  ///< hexes along the long direction (mat, plate, torus 40; bar 45; tori 48)
  int layers = 0;      ///< hexes through the thickness (1; plate and tori 3)
};

/// A name of enum_names<StructuredShape>() (tetseg/preprocess/names.hpp); throws
/// std::invalid_argument on an unknown name.
StructuredShape structured_shape_from_name(const std::string& name);

/// Builds the shape. Every hex is close to a cube (the thickness follows from the resolution
/// and the layers). The tori's tubes are 2 x 0.5 x layers x (2 pi / resolution) wide and their
/// centre circles 1 apart, so they do not touch for layers <= 4 at resolution >= 24. Throws
/// std::invalid_argument when resolution or layers are out of range (resolution 2..1000,
/// layers 1..64; tori need the tubes to stay apart).
TetMesh generate_structured(StructuredShape shape, const StructuredOptions& options);

}  // namespace tetseg::preprocess
