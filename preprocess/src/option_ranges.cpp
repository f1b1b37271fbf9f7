#include "tetseg/preprocess/option_ranges.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace tetseg::preprocess {
namespace {

/// The shortest text that reads back as `value` ("0.0001", not "0.00010000000000000000").
std::string number(double value) {
  char text[32];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
    if (std::strtod(text, nullptr) == value || std::isnan(value)) break;
  }
  return text;
}

}  // namespace

bool in_range(const OptionRange& range, double value) {
  const bool above_min = range.min_exclusive ? value > range.min : value >= range.min;
  return above_min && value <= range.max && !std::isnan(value);
}

void check_option(const OptionRange& range, double value) {
  if (in_range(range, value)) return;
  if (range.min_exclusive && range.min == 0.0 && std::isinf(range.max))
    throw std::invalid_argument(std::string(range.name) + " must be positive, got " +
                                number(value));
  throw std::invalid_argument(std::string(range.name) + " must be in [" + number(range.min) + ", " +
                              number(range.max) + "], got " + number(value));
}

}  // namespace tetseg::preprocess
