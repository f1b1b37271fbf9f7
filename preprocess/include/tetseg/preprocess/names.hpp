#pragma once
/// \file
/// One name table per option enum: the names the command-line tools accept, the reports print
/// and the asset provenance records. A value's first entry is its canonical name; later entries
/// for the same value are older spellings still accepted (aliases).

#include <map>
#include <string>
#include <vector>

#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/pipeline.hpp"
#include "tetseg/preprocess/segmentation.hpp"
#include "tetseg/preprocess/structured.hpp"

namespace tetseg::preprocess {

template <typename Enum>
struct EnumName {
  const char* name;
  Enum value;
};

/// The table of `Enum`: every value once under its canonical name, in declaration order, then
/// the aliases. Defined for ChargeSolver, ChargePreconditioner, Equalization, DetectorStrategy,
/// ClusterMethod, Shape, StructuredShape, MeshingOptions::Repair, format::BodyKind and
/// format::DetectorForm.
template <typename Enum>
const std::vector<EnumName<Enum>>& enum_names();

template <>
const std::vector<EnumName<ChargeSolver>>& enum_names<ChargeSolver>();
template <>
const std::vector<EnumName<ChargePreconditioner>>& enum_names<ChargePreconditioner>();
template <>
const std::vector<EnumName<Equalization>>& enum_names<Equalization>();
template <>
const std::vector<EnumName<DetectorStrategy>>& enum_names<DetectorStrategy>();
template <>
const std::vector<EnumName<ClusterMethod>>& enum_names<ClusterMethod>();
template <>
const std::vector<EnumName<Shape>>& enum_names<Shape>();
template <>
const std::vector<EnumName<StructuredShape>>& enum_names<StructuredShape>();

template <>
const std::vector<EnumName<MeshingOptions::Repair>>& enum_names<MeshingOptions::Repair>();
template <>
const std::vector<EnumName<format::BodyKind>>& enum_names<format::BodyKind>();
template <>
const std::vector<EnumName<format::DetectorForm>>& enum_names<format::DetectorForm>();

/// The canonical name of `value`.
template <typename Enum>
const char* name_of(Enum value) {
  for (const EnumName<Enum>& entry : enum_names<Enum>()) {
    if (entry.value == value) return entry.name;
  }
  return "?";
}

/// Sets `value` from a canonical name or an alias (exact, case-sensitive); false otherwise.
template <typename Enum>
bool parse_name(const std::string& text, Enum& value) {
  for (const EnumName<Enum>& entry : enum_names<Enum>()) {
    if (text == entry.name) {
      value = entry.value;
      return true;
    }
  }
  return false;
}

/// The canonical names joined by `separator` ("auto|direct|gmres|fast"), for help texts.
template <typename Enum>
std::string name_list(const char* separator = "|") {
  std::string out;
  std::vector<Enum> seen;
  for (const EnumName<Enum>& entry : enum_names<Enum>()) {
    bool known = false;
    for (Enum v : seen) known = known || v == entry.value;
    if (known) continue;
    seen.push_back(entry.value);
    if (!out.empty()) out += separator;
    out += entry.name;
  }
  return out;
}

/// Every name and alias to its value (what CLI11's CheckedTransformer takes).
template <typename Enum>
std::map<std::string, Enum> name_map() {
  std::map<std::string, Enum> out;
  for (const EnumName<Enum>& entry : enum_names<Enum>()) out.emplace(entry.name, entry.value);
  return out;
}

}  // namespace tetseg::preprocess
