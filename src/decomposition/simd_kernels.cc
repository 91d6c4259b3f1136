// The vector policies and the run-time dispatch of simd_kernels.inc (see simd_kernels.h).
#include "decomposition/simd_kernels.h"

#include <atomic>
#include <cmath>
#include <cstdint>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define GYRODRIFT_HAS_AVX2_PATH 1
#else
#define GYRODRIFT_HAS_AVX2_PATH 0
#endif

namespace gyrodrift::decomposition::internal {
namespace {

#if defined(__SSE2__)
namespace baseline {
struct V {
  using R = __m128d;
  using M = __m128d;
  using C = __m128i;
  static constexpr int W = 2;
  static R Load(const double* p) { return _mm_loadu_pd(p); }
  static void Store(double* p, R v) { _mm_storeu_pd(p, v); }
  static R Set1(double v) { return _mm_set1_pd(v); }
  static R Iota(double b) { return _mm_add_pd(_mm_set1_pd(b), _mm_set_pd(1.0, 0.0)); }
  static R Add(R a, R b) { return _mm_add_pd(a, b); }
  static R Sub(R a, R b) { return _mm_sub_pd(a, b); }
  static R Mul(R a, R b) { return _mm_mul_pd(a, b); }
  static R Div(R a, R b) { return _mm_div_pd(a, b); }
  static R Abs(R a) { return _mm_andnot_pd(_mm_set1_pd(-0.0), a); }
  static M Greater(R a, R b) { return _mm_cmpgt_pd(a, b); }
  static unsigned SignBits(R v) { return static_cast<unsigned>(_mm_movemask_pd(v)); }
  static M EqZero(R v) { return _mm_cmpeq_pd(v, _mm_setzero_pd()); }
  static M LtZero(R v) { return _mm_cmplt_pd(v, _mm_setzero_pd()); }
  static M Or(M a, M b) { return _mm_or_pd(a, b); }
  static bool Any(M m) { return _mm_movemask_pd(m) != 0; }
  static C CountInit() { return _mm_setzero_si128(); }
  // A true lane is all ones, -1 as an integer: subtracting counts it.
  static C CountAdd(C c, M m) { return _mm_sub_epi64(c, _mm_castpd_si128(m)); }
  static std::int64_t CountSum(C c) {
    alignas(16) std::int64_t lanes[2];
    _mm_store_si128(reinterpret_cast<__m128i*>(lanes), c);
    return lanes[0] + lanes[1];
  }
};
#include "decomposition/simd_kernels.inc"
}  // namespace baseline
#else
namespace baseline {
struct V {  // portable scalar build
  using R = double;
  using M = bool;
  using C = std::int64_t;
  static constexpr int W = 1;
  static R Load(const double* p) { return *p; }
  static void Store(double* p, R v) { *p = v; }
  static R Set1(double v) { return v; }
  static R Iota(double b) { return b; }
  static R Add(R a, R b) { return a + b; }
  static R Sub(R a, R b) { return a - b; }
  static R Mul(R a, R b) { return a * b; }
  static R Div(R a, R b) { return a / b; }
  static R Abs(R a) { return std::fabs(a); }
  static M Greater(R a, R b) { return a > b; }
  static unsigned SignBits(R v) { return std::signbit(v) ? 1u : 0u; }
  static M EqZero(R v) { return v == 0.0; }
  static M LtZero(R v) { return v < 0.0; }
  static M Or(M a, M b) { return a || b; }
  static bool Any(M m) { return m; }
  static C CountInit() { return 0; }
  static C CountAdd(C c, M m) { return c + (m ? 1 : 0); }
  static std::int64_t CountSum(C c) { return c; }
};
#include "decomposition/simd_kernels.inc"
}  // namespace baseline
#endif

#if GYRODRIFT_HAS_AVX2_PATH
// Every function of the AVX2 path is compiled for AVX2 (chosen at run time by the CPU); clang
// spells GCC's target pragma as an attribute applied to each function.
#if defined(__clang__)
#pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#else
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace avx2 {
struct V {
  using R = __m256d;
  using M = __m256d;
  using C = __m256i;
  static constexpr int W = 4;
  static R Load(const double* p) { return _mm256_loadu_pd(p); }
  static void Store(double* p, R v) { _mm256_storeu_pd(p, v); }
  static R Set1(double v) { return _mm256_set1_pd(v); }
  static R Iota(double b) {
    return _mm256_add_pd(_mm256_set1_pd(b), _mm256_set_pd(3.0, 2.0, 1.0, 0.0));
  }
  static R Add(R a, R b) { return _mm256_add_pd(a, b); }
  static R Sub(R a, R b) { return _mm256_sub_pd(a, b); }
  static R Mul(R a, R b) { return _mm256_mul_pd(a, b); }
  static R Div(R a, R b) { return _mm256_div_pd(a, b); }
  static R Abs(R a) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), a); }
  static M Greater(R a, R b) { return _mm256_cmp_pd(a, b, _CMP_GT_OQ); }
  static unsigned SignBits(R v) { return static_cast<unsigned>(_mm256_movemask_pd(v)); }
  static M EqZero(R v) { return _mm256_cmp_pd(v, _mm256_setzero_pd(), _CMP_EQ_OQ); }
  static M LtZero(R v) { return _mm256_cmp_pd(v, _mm256_setzero_pd(), _CMP_LT_OQ); }
  static M Or(M a, M b) { return _mm256_or_pd(a, b); }
  static bool Any(M m) { return _mm256_movemask_pd(m) != 0; }
  static C CountInit() { return _mm256_setzero_si256(); }
  static C CountAdd(C c, M m) { return _mm256_sub_epi64(c, _mm256_castpd_si256(m)); }
  static std::int64_t CountSum(C c) {
    alignas(32) std::int64_t lanes[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), c);
    return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
  }
};
#include "decomposition/simd_kernels.inc"
}  // namespace avx2
#if defined(__clang__)
#pragma clang attribute pop
#else
#pragma GCC pop_options
#endif
#endif

std::atomic<int> requested_path{static_cast<int>(SimdPath::kAuto)};

bool UseAvx2() {
  return requested_path.load(std::memory_order_relaxed) != static_cast<int>(SimdPath::kBaseline) &&
         SimdAvx2Available();
}

}  // namespace

bool SimdAvx2Available() {
#if GYRODRIFT_HAS_AVX2_PATH
  static const bool available = [] {
    __builtin_cpu_init();  // safe before static constructors have run
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return available;
#else
  return false;
#endif
}

void SetSimdPath(SimdPath path) {
  requested_path.store(static_cast<int>(path), std::memory_order_relaxed);
}

#if GYRODRIFT_HAS_AVX2_PATH
#define GYRODRIFT_DISPATCH(call) (UseAvx2() ? avx2::call : baseline::call)
#else
#define GYRODRIFT_DISPATCH(call) baseline::call
#endif

void SimdEvaluate(const SplineView& s, Eigen::Index n, double* out) {
  GYRODRIFT_DISPATCH(Evaluate(s, n, out));
}

void SimdEvaluateSift(const SplineView& s, Eigen::Index n, const double* lower, const double* h,
                      double* next) {
  GYRODRIFT_DISPATCH(EvaluateSift(s, n, lower, h, next));
}

bool SimdFindStrictExtrema(const double* x, Eigen::Index n, bool zero_crossings, ExtremaScan* out) {
  return GYRODRIFT_DISPATCH(FindStrictExtrema(x, n, zero_crossings, out));
}

RillingCounts SimdRillingSift(const double* lo, const double* hi, const double* h, double* next,
                              Eigen::Index n, double threshold1, double threshold2) {
  return GYRODRIFT_DISPATCH(RillingSift(lo, hi, h, next, n, threshold1, threshold2));
}

#undef GYRODRIFT_DISPATCH

}  // namespace gyrodrift::decomposition::internal
