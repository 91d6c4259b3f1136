#include "format.h"

#include <cstdarg>
#include <cstdio>

namespace gyrodrift::internal {

std::string Format(const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int length = std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  std::string out;
  if (length >= 0 && static_cast<size_t>(length) < sizeof(buffer)) {
    out.assign(buffer, static_cast<size_t>(length));
  } else if (length >= 0) {  // longer than the buffer (a ULog listing line of many fields)
    out.resize(static_cast<size_t>(length));
    std::vsnprintf(out.data(), out.size() + 1, format, again);
  }
  va_end(again);
  return out;
}

}  // namespace gyrodrift::internal
