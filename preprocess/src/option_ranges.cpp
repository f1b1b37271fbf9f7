#include "tetseg/preprocess/option_ranges.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace tetseg::preprocess {
namespace {

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
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
