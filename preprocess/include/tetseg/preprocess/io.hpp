#pragma once
/// \file
/// Reading and writing meshes. Every reader throws InputError naming the file and the problem
/// (with a line number for text formats) and never returns a partially read mesh.

#include <string>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// Tet mesh formats by extension: MEDIT `.mesh` (ASCII), TetGen `.node`+`.ele` (give either
/// file; the other is found beside it), Gmsh `.msh` 2.2 and 4.1 (ASCII).
bool is_tet_mesh_path(const std::string& path);

/// Reads a tetrahedral mesh; the format follows from the extension. Checks syntax and index
/// ranges and finite coordinates, not geometry (see validate.hpp). Throws InputError.
TetMesh read_tet_mesh(const std::string& path);

/// Writes a tetrahedral mesh in the format named by the extension (`.mesh`, `.node`/`.ele`,
/// `.msh` writes Gmsh 4.1; `.msh22` is not an extension: use write_gmsh22). Writes the bytes
/// to `path` directly (callers that need atomicity write to a temporary path and rename).
/// Throws OutputError.
void write_tet_mesh(const std::string& path, const TetMesh& mesh);
void write_gmsh22(const std::string& path, const TetMesh& mesh);

/// Reads a triangle surface through assimp (OBJ, PLY, STL, OFF, glTF, ...), merging
/// coincident vertices. Throws InputError.
TriangleMesh read_triangle_mesh(const std::string& path);

}  // namespace tetseg::preprocess
