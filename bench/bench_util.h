// Shared by the benchmark programs.
#pragma once

#include <cstdlib>
#include <cstring>

namespace gyrodrift::bench {

// CTest runs every benchmark once with GYRODRIFT_BENCH_SMOKE=1: programs then register small
// sizes only, so the smoke run proves the code path without spending CI minutes.
inline bool SmokeMode() {
  const char* v = std::getenv("GYRODRIFT_BENCH_SMOKE");
  return v != nullptr && std::strcmp(v, "0") != 0;
}

}  // namespace gyrodrift::bench
