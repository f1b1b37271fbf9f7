// The name tables (names.hpp): every value has exactly one canonical name, first in the
// table; names and aliases parse back to their value; the canonical names are the ones the
// documentation and old assets use.

#include <catch2/catch.hpp>
#include <set>
#include <string>

#include "tetseg/preprocess/names.hpp"

using namespace tetseg::preprocess;

namespace {

// Canonical names in declaration order, aliases accepted, unknown names refused.
template <typename Enum>
void check_table(const std::vector<std::string>& canonical) {
  std::set<std::string> names;
  std::string joined;
  for (const EnumName<Enum>& entry : enum_names<Enum>()) {
    CHECK(names.insert(entry.name).second);  // no name twice
    Enum parsed{};
    REQUIRE(parse_name(entry.name, parsed));
    CHECK(parsed == entry.value);
  }
  for (std::size_t i = 0; i < canonical.size(); ++i) {
    const Enum value = static_cast<Enum>(i);
    CHECK(name_of(value) == canonical[i]);
    joined += (i ? "|" : "") + canonical[i];
  }
  CHECK(name_list<Enum>() == joined);
  Enum unchanged = static_cast<Enum>(0);
  CHECK_FALSE(parse_name("no-such-name", unchanged));
  CHECK(unchanged == static_cast<Enum>(0));
}

}  // namespace

TEST_CASE("Every option enum has one name table with canonical names first", "[names]") {
  check_table<ChargeSolver>({"auto", "direct", "gmres", "fast"});
  check_table<ChargePreconditioner>({"jacobi", "block", "near-field", "two-level"});
  check_table<Equalization>({"histogram", "rank", "log-histogram"});
  check_table<DetectorStrategy>({"nearest-centroid", "visibility"});
  check_table<ClusterMethod>({"single", "charge", "refined"});
  check_table<Shape>({"sphere", "ellipsoid", "dumbbell", "pawn"});
}

TEST_CASE("Older spellings stay accepted as aliases", "[names]") {
  Equalization equalization{};
  REQUIRE(parse_name("log", equalization));  // `tetseg charge --equalize log`
  CHECK(equalization == Equalization::kLogHistogram);
  ChargePreconditioner preconditioner{};
  REQUIRE(parse_name("two", preconditioner));  // tetseg-bench-charge "gmres/two"
  CHECK(preconditioner == ChargePreconditioner::kTwoLevel);
  REQUIRE(parse_name("near", preconditioner));
  CHECK(preconditioner == ChargePreconditioner::kNearField);
  CHECK(name_map<Equalization>().size() == 4);
}
