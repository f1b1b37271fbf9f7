#pragma once
/// \file
/// Reading a coloured PLY surface for tetseg-render (e.g. `tetseg charge -o x.ply`).

#include <string>

#include "render.hpp"

namespace tetseg::tools {

/// Reads a PLY surface with per-face colours: ASCII or binary little/big endian; vertex x,y,z
/// of any numeric type; faces as a list of indices (polygons triangulated as fans); face
/// red/green/blue as uchar, or as float/double in [0,1]; faces without colour are grey; other
/// elements and properties are skipped. Safe on hostile input: counts are checked against the
/// file size before anything is allocated. Throws ToolError(kExitBadInput, path, ...) naming
/// the problem (reading through tetseg_mesh_io). When `scalar_property` names a face property (e.g.
/// "charge"), faces are coloured by it instead: scalar_color of the value rescaled from [min, max]
/// to [0, 1]; a missing property is bad input.
RenderMesh read_colored_ply(const std::string& path, const std::string& scalar_property = {});

}  // namespace tetseg::tools
