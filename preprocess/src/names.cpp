#include "tetseg/preprocess/names.hpp"

#include <stdexcept>

namespace tetseg::preprocess {

template <>
const std::vector<EnumName<ChargeSolver>>& enum_names<ChargeSolver>() {
  static const std::vector<EnumName<ChargeSolver>> table = {{"auto", ChargeSolver::kAuto},
                                                            {"direct", ChargeSolver::kDirect},
                                                            {"gmres", ChargeSolver::kGmres},
                                                            {"fast", ChargeSolver::kFast}};
  return table;
}

template <>
const std::vector<EnumName<ChargePreconditioner>>& enum_names<ChargePreconditioner>() {
  static const std::vector<EnumName<ChargePreconditioner>> table = {
      {"jacobi", ChargePreconditioner::kJacobi},
      {"block", ChargePreconditioner::kBlock},
      {"near-field", ChargePreconditioner::kNearField},
      {"two-level", ChargePreconditioner::kTwoLevel},
      {"near", ChargePreconditioner::kNearField},  // tetseg-bench-charge's short names
      {"two", ChargePreconditioner::kTwoLevel}};
  return table;
}

template <>
const std::vector<EnumName<Equalization>>& enum_names<Equalization>() {
  static const std::vector<EnumName<Equalization>> table = {
      {"histogram", Equalization::kHistogram},
      {"rank", Equalization::kRank},
      {"log-histogram", Equalization::kLogHistogram},
      {"log", Equalization::kLogHistogram}};  // `tetseg charge --equalize log` before 0.2
  return table;
}

template <>
const std::vector<EnumName<DetectorStrategy>>& enum_names<DetectorStrategy>() {
  static const std::vector<EnumName<DetectorStrategy>> table = {
      {"nearest-centroid", DetectorStrategy::kNearestCentroid},
      {"visibility", DetectorStrategy::kVisibility}};
  return table;
}

template <>
const std::vector<EnumName<ClusterMethod>>& enum_names<ClusterMethod>() {
  static const std::vector<EnumName<ClusterMethod>> table = {{"single", ClusterMethod::kSingle},
                                                             {"charge", ClusterMethod::kCharge},
                                                             {"refined", ClusterMethod::kRefined}};
  return table;
}

template <>
const std::vector<EnumName<Shape>>& enum_names<Shape>() {
  static const std::vector<EnumName<Shape>> table = {{"sphere", Shape::kSphere},
                                                     {"ellipsoid", Shape::kEllipsoid},
                                                     {"dumbbell", Shape::kDumbbell},
                                                     {"pawn", Shape::kPawn}};
  return table;
}

template <>
const std::vector<EnumName<StructuredShape>>& enum_names<StructuredShape>() {
  static const std::vector<EnumName<StructuredShape>> table = {{"mat", StructuredShape::kMat},
                                                               {"plate", StructuredShape::kPlate},
                                                               {"bar", StructuredShape::kBar},
                                                               {"torus", StructuredShape::kTorus},
                                                               {"tori", StructuredShape::kTori}};
  return table;
}

template <>
const std::vector<EnumName<MeshingOptions::Repair>>& enum_names<MeshingOptions::Repair>() {
  using Repair = MeshingOptions::Repair;
  static const std::vector<EnumName<Repair>> table = {{"none", Repair::kNone},
                                                      {"fix", Repair::kFix},
                                                      {"wrap", Repair::kWrap},
                                                      {"auto", Repair::kAuto}};
  return table;
}

Shape shape_from_name(const std::string& name) {
  Shape shape;
  if (!parse_name(name, shape)) {
    throw std::invalid_argument("unknown shape '" + name + "' (expected " + name_list<Shape>(", ") +
                                ")");
  }
  return shape;
}

template <>
const std::vector<EnumName<format::BodyKind>>& enum_names<format::BodyKind>() {
  static const std::vector<EnumName<format::BodyKind>> table = {
      {"tet", format::BodyKind::kTet}, {"surface", format::BodyKind::kSurface}};
  return table;
}

template <>
const std::vector<EnumName<format::DetectorForm>>& enum_names<format::DetectorForm>() {
  static const std::vector<EnumName<format::DetectorForm>> table = {
      {"tet", format::DetectorForm::kTetPoint},
      {"weights", format::DetectorForm::kSurfaceWeights},
      {"skin", format::DetectorForm::kBones}};
  return table;
}

}  // namespace tetseg::preprocess
