// Private: printf-style formatting into a string, for the messages and report lines of the core
// library, which links no formatting library.
#pragma once

#include <string>

namespace gyrodrift::internal {

// The text of `format` with its arguments, whole however long.
std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace gyrodrift::internal
