// Private: enum <-> name tables shared by every module's ToString / FromString helpers, so the
// CLI, metadata and messages use one spelling and one error message shape.
#pragma once

#include <array>
#include <string>
#include <string_view>
#include <utility>

#include "gyrodrift/common/check.h"

namespace gyrodrift::internal {

template <class E, size_t N>
using EnumNames = std::array<std::pair<E, std::string_view>, N>;

// The name of `value` in the table ("?" if it is missing).
template <class E, size_t N>
std::string_view EnumName(E value, const EnumNames<E, N>& names) {
  for (const auto& [v, name] : names) {
    if (v == value) return name;
  }
  return "?";
}

// The value named `text`; throws UsageError "<what> = '<text>': must be one of a, b, c".
template <class E, size_t N>
E EnumFromName(std::string_view text, std::string_view what, const EnumNames<E, N>& names) {
  std::string allowed;
  for (const auto& [v, name] : names) {
    if (name == text) return v;
    allowed += (allowed.empty() ? "" : ", ") + std::string(name);
  }
  ThrowOption(what, "'" + std::string(text) + "'", "one of " + allowed);
}

}  // namespace gyrodrift::internal
