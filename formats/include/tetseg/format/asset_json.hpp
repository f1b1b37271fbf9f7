#pragma once
/// \file
/// The JSON pieces that describe an asset, shared by every JSON writer that prints one (the
/// build report of tetseg::preprocess, `tetseg-dump --json`), so they print it the same way.
/// Standard library only; deterministic; thread-safe.

#include <string>

#include "tetseg/format/asset.hpp"

namespace tetseg::format {

/// Escapes `text` for a JSON string literal (without the surrounding quotes): quote,
/// backslash, and control characters (as \n, \t, \r or \u00XX); other bytes as they are.
std::string json_escape(const std::string& text);

/// Short stable names: "tet", "surface"; "tet-point", "surface-weights", "bones" ("unknown"
/// for a value outside the enum).
const char* body_kind_name(BodyKind kind) noexcept;
const char* detector_form_name(DetectorForm form) noexcept;

/// A cluster's detector and flag as JSON members (no braces). kTetPoint: `"detector":
/// {"nodes": [4 ids], "weights": [4], "tet": id or null, "position": [x, y, z] (the rest
/// position, when `asset` has rest positions, else omitted)}, "overlap_only": bool`. Other
/// forms: `"detector": {"form": "surface-weights" or "bones", "terms": [[index, weight], ...],
/// "position": [x, y, z] (detector_rest)}, "overlap_only": bool`. Numbers at 17 digits.
std::string detector_json(const Asset& asset, const Cluster& cluster);

/// The provenance options as one JSON object of strings, in recorded order:
/// `{"key": "value", ...}`.
std::string provenance_options_json(const Asset& asset);

}  // namespace tetseg::format
