#pragma once
// The tables of broken validation rules (asset_validate_test.cpp, asset_v12_test.cpp): each
// rule broken once on a valid asset, and the one check that the result is refused.

#include <catch2/catch.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "format/support/test_assets.hpp"

namespace tetseg::test {

/// One validation rule broken once: `breaks` turns `valid()` into an asset that breaks the rule
/// called `name`; validate()'s detail message must contain `expect` (the rule that fires).
struct BrokenRule {
  const char* name;
  const char* expect;
  std::function<void(Asset&)> breaks;
  Asset (*valid)() = make_octahedron_asset;
};

/// Checks that the asset `rule` breaks is refused: valid() passes validate(), the broken asset
/// fails it with `rule.expect` in the detail, and read_asset() refuses its written bytes and
/// leaves its output empty. Returns those bytes. The caller captures rule.name.
inline std::vector<std::uint8_t> check_refused(const BrokenRule& rule) {
  Asset broken = rule.valid();
  REQUIRE(format::validate(broken) == format::Status::kOk);
  rule.breaks(broken);
  std::string why;
  CHECK(format::validate(broken, &why) == format::Status::kInvalidContent);
  CHECK_FALSE(why.empty());
  INFO(why);
  CHECK(why.find(rule.expect) != std::string::npos);
  const std::vector<std::uint8_t> bytes = format::write_asset(broken);
  Asset out = make_cube_asset(1);
  std::string read_why;
  CHECK(format::read_asset(bytes.data(), bytes.size(), out, &read_why) ==
        format::Status::kInvalidContent);
  CHECK(is_empty(out));
  CHECK_FALSE(read_why.empty());
  return bytes;
}

}  // namespace tetseg::test
