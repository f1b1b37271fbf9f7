#pragma once
/// \file
/// Reading and writing meshes. Every reader throws InputError naming the file and the problem
/// (with a line number for text formats) and never returns a partially read mesh.

#include <string>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess {

/// Tet mesh formats by extension: MEDIT `.mesh` (ASCII), TetGen `.node`+`.ele` (give either
/// file; the other is found beside it), Gmsh `.msh` 2.2 and 4.1, ASCII or binary (either byte
/// order, found by the format's endianness check; 4.1 with 4- or 8-byte size fields).
bool is_tet_mesh_path(const std::string& path);

/// Reads a tetrahedral mesh; the format follows from the extension (case-insensitive). Nodes
/// get 0-based ids in file order (all nodes of the file, also those no tet uses; Gmsh tags
/// and TetGen's 0/1-based ids are mapped). Only 4-node tets are kept (10-node tets: their
/// corner nodes); other elements (triangles, edges, ...) are ignored, as are unknown MEDIT
/// sections and Gmsh `$Sections`. If every tet with nonzero volume is negatively oriented
/// (a mirrored convention), two vertices of every tet are swapped; mixed orientations are
/// left for validate_tet_mesh to report. Checks syntax, counts, index ranges and finite
/// coordinates, not geometry. Throws InputError(path, "line N: ...") for malformed text,
/// unexpected end of file, indices out of range, NaN/Inf, counts that do not match (binary
/// Gmsh: "byte N: ..." instead of a line); "no tetrahedra in file" when there are none. Safe
/// on untrusted input (counts are checked against the bytes left before reserving or reading).
/// Thread-safe (no shared state).
TetMesh read_tet_mesh(const std::string& path);

/// Writes a tetrahedral mesh in the format named by the extension (`.mesh`, `.node`/`.ele`,
/// `.msh` writes Gmsh 4.1; `.msh22` is not an extension: use write_gmsh22). Writes the bytes
/// to `path` directly (callers that need atomicity write to a temporary path and rename).
/// Throws OutputError.
void write_tet_mesh(const std::string& path, const TetMesh& mesh);
void write_gmsh22(const std::string& path, const TetMesh& mesh);
/// Gmsh 4.1 binary (little-endian, 8-byte size fields): one volume entity, node and tet tags
/// from 1. Reads back bit-exactly with read_tet_mesh. Throws OutputError.
void write_gmsh41_binary(const std::string& path, const TetMesh& mesh);

/// Reads a triangle surface. OFF (ASCII), PLY, OBJ and STL go through CGAL's polygon-soup
/// readers (double precision); polygons with more than three corners are triangulated (CGAL's
/// hole triangulation of the polygon's outline, so non-planar quads are split sensibly). Other
/// formats (glTF, FBX, 3DS, ...) go through assimp (single-precision floats; node transforms
/// applied). Points and lines are dropped, and vertices with exactly the same position merged
/// (numbered in order of first use). Throws InputError naming the file when it cannot be read
/// or holds no triangles; whatever CGAL or assimp throws (also allocation failures) becomes an
/// InputError too. Safe on untrusted input: before CGAL's readers size anything, OFF header
/// counts and face lengths, and every PLY element count and list length, are checked against
/// the bytes (or tokens) that follow; binary OFF is refused; NaN/Inf coordinates, out-of-range
/// indices and polygons of more than 4096 corners are refused. No validation: see
/// validate_closed_surface.
TriangleMesh read_triangle_mesh(const std::string& path);

/// read_triangle_mesh for a surface body (`tetseg build --body surface`): OFF, PLY and OBJ
/// keep the file's vertices as they are, all of them in their order (none merged or dropped),
/// so that frames of the same simulation apply unchanged; polygons are triangulated as there.
/// STL (corners repeated per facet) and the assimp formats merge vertices by exact position
/// (numbered in order of first use) and, when `source_vertex_nodes` is given, set it to the
/// vertex each vertex of the file became (format::Asset::source_vertex_nodes): STL's file
/// vertices are the facets' corners, three per facet in file order; an assimp format's are
/// assimp's meshes' vertices in order, unjoined (a glTF with one mesh: its POSITION
/// accessor's order, split at seams), and unused ones become vertices too. OFF, PLY and OBJ
/// leave it empty (vertex i is the file's vertex i).
TriangleMesh read_triangle_mesh_keeping_vertices(
    const std::string& path, std::vector<std::uint32_t>* source_vertex_nodes = nullptr);

}  // namespace tetseg::preprocess
