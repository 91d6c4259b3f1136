#include "decomposition/spline.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cstdint>

#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace gyrodrift::decomposition::internal {

void ReleasePages(void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_DONTNEED)
  static const uintptr_t page = static_cast<uintptr_t>(sysconf(_SC_PAGESIZE));
  const uintptr_t begin = (reinterpret_cast<uintptr_t>(p) + page - 1) / page * page;
  const uintptr_t end = (reinterpret_cast<uintptr_t>(p) + bytes) / page * page;
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_DONTNEED);
#else
  (void)p;
  (void)bytes;
#endif
}

void EnvelopeSpline::ReleaseStorage() {
  ReleasePages(t_.data(), t_.capacity() * sizeof(double));
  ReleasePages(y_.data(), y_.capacity() * sizeof(double));
  ReleasePages(storage_.data(), storage_.size() * sizeof(double));
}

EnvelopeSpline::EnvelopeSpline(Eigen::Index max_nodes, int phase) {
  const size_t size = static_cast<size_t>(max_nodes) + 1;
  t_.reserve(size);
  y_.reserve(size);
  // The seven per-node arrays share one allocation, each starting 320 bytes further round the
  // 4 KiB page than the previous one (and phase 1 another 160 bytes): equal arrays allocated
  // apart would all start at the same offset in the page, and the sweeps, which walk all of
  // them (of both splines) at once, would compete for the same cache sets.
  const size_t stride = (size + 511) / 512 * 512 + 40;
  const size_t offset = 20 * static_cast<size_t>(phase);
  storage_.resize(7 * stride + offset);  // written before read, node by node
  double* base = storage_.data() + offset;
  for (double** p : {&inv_dx_, &dd_, &slope_, &diag_, &rhs_, &c1_, &c2_}) {
    *p = base;
    base += stride;
  }
}

// Not-a-knot slopes from the tridiagonal system (MATLAB spline.m), row j:
//   sub[j] s[j-1] + diag[j] s[j] + sup[j] s[j+1] = rhs[j],
// interior rows sub = dx_j, diag = 2 (dx_j + dx_{j-1}), sup = dx_{j-1},
// rhs = 3 (dx_j dd_{j-1} + dx_{j-1} dd_j), and rows 0 and m-1 carrying the not-a-knot conditions.
// The rows are built inside the elimination sweep, which is bound by its division chain, so
// building them there costs no extra time and nothing but the inverse pivots and the eliminated
// right-hand side is stored; the cubic coefficients are likewise made in the back substitution.
// Every quantity is the same expression, in the same order, as the plain three-pass form.
//
// Both sweeps are chains of dependent operations (the elimination's through a division), so one
// sweep runs at the latency of its chain while most of the processor idles. Independent chains
// are therefore interleaved row by row: the two envelopes' sweeps, and for long systems
// kChunks pieces of each sweep. A piece cannot know the state the piece before it will hand
// over, so it starts kWarmUp rows early from a guess. The sweeps of this diagonally dominant
// system forget their past geometrically (by about 0.27 per row for evenly spaced nodes), so
// after the warm-up the guessed state is, but for freak cases, the true one to the last bit,
// and from there every row is the same computation as in one plain sweep. Each piece's start is
// checked against its predecessor's end once both have run; a piece that started from another
// state is recomputed from the true one. The result is the plain sweep's, bit for bit.
namespace {

void DividedDifferences(const double* __restrict t, const double* __restrict y,
                        double* __restrict inv_dx, double* __restrict dd, size_t m) {
  for (size_t j = 0; j + 1 < m; ++j) {
    inv_dx[j] = 1.0 / (t[j + 1] - t[j]);
    dd[j] = (y[j + 1] - y[j]) * inv_dx[j];
  }
}

// The per-node arrays of one spline's system.
struct System {
  size_t m;
  const double* t;
  const double* dd;
  const double* inv_dx;
  double* inv_diag;  // inverse pivots
  double* rhs;       // eliminated right-hand side
  double* slope;
  double* c1;
  double* c2;
};

// What the elimination carries from row j-1 to row j.
struct Elimination {
  double inv, rhs;
};

// Equal to the last bit (0.0 == -0.0, but the rows after them can differ).
bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}
bool SameBits(const Elimination& a, const Elimination& b) {
  return SameBits(a.inv, b.inv) && SameBits(a.rhs, b.rhs);
}

// Row j of the elimination (1 <= j <= m-2; sup_prev is row j-1's super-diagonal) from the
// state after row j-1; stores the row's inverse pivot and right-hand side, returns the state.
[[gnu::always_inline]] inline Elimination EliminateRow(const System& s, size_t j, double sup_prev,
                                                       Elimination e) {
  const double* t = s.t;
  const double* dd = s.dd;
  const double dx_j = t[j + 1] - t[j];
  const double dx_prev = t[j] - t[j - 1];
  const double diag = 2 * (dx_j + dx_prev);
  const double rhs = 3 * (dx_j * dd[j - 1] + dx_prev * dd[j]);
  const double w = dx_j * e.inv;
  e.inv = 1.0 / (diag - w * sup_prev);
  e.rhs = rhs - w * e.rhs;
  s.inv_diag[j] = e.inv;
  s.rhs[j] = e.rhs;
  return e;
}

// Rows 0 and 1 (row 0 carries the not-a-knot condition); returns the state after row 1.
Elimination FirstRows(const System& s) {
  const double* t = s.t;
  const double* dd = s.dd;
  const double dx0 = t[1] - t[0], dx1 = t[2] - t[1];
  const double x31 = t[2] - t[0];
  const double inv0 = s.inv_diag[0] = 1.0 / dx1;
  const double rhs0 = s.rhs[0] = ((dx0 + 2 * x31) * dx1 * dd[0] + dx0 * dx0 * dd[1]) / x31;
  return EliminateRow(s, 1, x31, {inv0, rhs0});
}

// Interior rows row[k], row[k] + 1, ... (2 <= row, up to m-2) of K chains, `steps` rows each,
// interleaved; state[k] goes in as the state before the first row and comes out after the last.
template <size_t K, class At>
void EliminateRows(At at, size_t (&row)[K], Elimination (&state)[K], size_t steps) {
  Elimination carried[K];  // a local copy: the stores below could alias `state` for the compiler
  std::copy(state, state + K, carried);
  for (size_t r = 0; r < steps; ++r) {
#pragma GCC unroll 4
    for (size_t k = 0; k < K; ++k) {
      const System& s = at(k);
      const size_t j = row[k] + r;
      carried[k] = EliminateRow(s, j, s.t[j - 1] - s.t[j - 2], carried[k]);
    }
  }
  std::copy(carried, carried + K, state);
  for (size_t k = 0; k < K; ++k) row[k] += steps;
}

// Row m-1 (the other not-a-knot condition), from the state after row m-2.
void LastRow(const System& s, const Elimination& e) {
  const double* t = s.t;
  const size_t m = s.m;
  const double dxl = t[m - 1] - t[m - 2], dxl1 = t[m - 2] - t[m - 3];
  const double xn = t[m - 1] - t[m - 3];
  const double rhs = (dxl * dxl * s.dd[m - 3] + (2 * xn + dxl) * dxl1 * s.dd[m - 2]) / xn;
  const double w = xn * e.inv;
  s.inv_diag[m - 1] = 1.0 / (dxl1 - w * (t[m - 2] - t[m - 3]));
  s.rhs[m - 1] = rhs - w * e.rhs;
}

// Row j of the back substitution s[j] = (rhs[j] - sup[j] s[j+1]) inv_diag[j], with piece j's
// cubic coefficients (MATLAB pwch): v = ((c1 h + c2) h + slope) h + y. next is s[j+1]; returns
// s[j].
[[gnu::always_inline]] inline double SubstituteRow(const System& s, size_t j, double sup,
                                                   double next) {
  const double slope = (s.rhs[j] - sup * next) * s.inv_diag[j];
  s.slope[j] = slope;
  const double dzzdx = (s.dd[j] - slope) * s.inv_dx[j];
  const double dzdxdx = (next - s.dd[j]) * s.inv_dx[j];
  s.c1[j] = (dzdxdx - dzzdx) * s.inv_dx[j];
  s.c2[j] = 2 * dzzdx - dzdxdx;
  return slope;
}

// Rows row[k], row[k] - 1, ... (down to 1 at the lowest) of K chains, `steps` each,
// interleaved; next[k] is s[row + 1] going in and the last slope made coming out.
template <size_t K, class At>
void SubstituteRows(At at, size_t (&row)[K], double (&next)[K], size_t steps) {
  double slope_after[K];  // a local copy, as in EliminateRows
  std::copy(next, next + K, slope_after);
  for (size_t r = 0; r < steps; ++r) {
#pragma GCC unroll 4
    for (size_t k = 0; k < K; ++k) {
      const System& s = at(k);
      const size_t j = row[k] - r;
      slope_after[k] = SubstituteRow(s, j, s.t[j] - s.t[j - 1], slope_after[k]);
    }
  }
  std::copy(slope_after, slope_after + K, next);
  for (size_t k = 0; k < K; ++k) row[k] -= steps;
}

// Slope m-1, where the back substitution starts.
double LastSlope(const System& s) {
  return s.slope[s.m - 1] = s.rhs[s.m - 1] * s.inv_diag[s.m - 1];
}
// Row 0, whose super-diagonal is the not-a-knot one, from s[1].
void FirstPiece(const System& s, double next) { SubstituteRow(s, 0, s.t[2] - s.t[0], next); }

// The two sweeps as policies for RunSweep: the elimination runs over rows 2 .. m-2 upwards, the
// substitution over rows m-2 .. 1 downwards; `Row(s, k)` is the k-th row in sweep order.
struct EliminationSweep {
  using State = Elimination;
  static size_t Rows(const System& s) { return s.m - 3; }
  static size_t Row(const System&, size_t k) { return 2 + k; }
  // A state to start a warm-up at row j from: that of evenly spaced nodes, whose pivot is
  // (2 + sqrt 3) / 2 times the diagonal and whose eliminated right-hand side is the raw one over
  // 1 + (2 - sqrt 3).
  static State Guess(const System& s, size_t j) {
    const double dx = s.t[j] - s.t[j - 1], dx_prev = s.t[j - 1] - s.t[j - 2];
    return {1.0 / (1.866 * (dx + dx_prev)), 3 * (dx * s.dd[j - 2] + dx_prev * s.dd[j - 1]) / 1.27};
  }
  template <size_t K, class At>
  static void Run(At at, size_t (&row)[K], State (&state)[K], size_t steps) {
    EliminateRows(at, row, state, steps);
  }
};

struct SubstitutionSweep {
  using State = double;
  static size_t Rows(const System& s) { return s.m - 2; }
  static size_t Row(const System& s, size_t k) { return s.m - 2 - k; }
  static State Guess(const System& s, size_t j) { return s.dd[j + 1]; }  // the secant slope
  template <size_t K, class At>
  static void Run(At at, size_t (&row)[K], State (&state)[K], size_t steps) {
    SubstituteRows(at, row, state, steps);
  }
};

template <class Sweep>
void RunOne(const System& s, size_t row, typename Sweep::State& state, size_t steps) {
  size_t r[1] = {row};
  typename Sweep::State st[1] = {state};
  Sweep::Run([&s](size_t) -> const System& { return s; }, r, st, steps);
  state = st[0];
}

// A system's sweep cut into kChunks pieces of equal cost, counted in sweep order: piece 0 starts
// from the true state and has warm_up more rows; piece c > 0 first runs over the last warm_up rows
// of piece c-1 (writing values that piece c-1 overwrites later, as it reaches them after that).
constexpr size_t kChunks = 4;

template <class Sweep>
void RunChunked(const System& s, typename Sweep::State& state, size_t warm_up) {
  using State = typename Sweep::State;
  const size_t rows = Sweep::Rows(s);
  const size_t each = (rows - warm_up) / kChunks;
  size_t first[kChunks + 1] = {0, each + warm_up};  // piece c: rows [first[c], first[c+1])
  for (size_t c = 2; c < kChunks; ++c) first[c] = first[c - 1] + each;
  first[kChunks] = rows;
  size_t row[kChunks];
  State st[kChunks];
  for (size_t c = 0; c < kChunks; ++c) {
    row[c] = Sweep::Row(s, c == 0 ? 0 : first[c] - warm_up);
    st[c] = c == 0 ? state : Sweep::Guess(s, row[c]);
  }
  // One system for every chain: the compiler keeps its arrays' addresses in registers.
  const auto same = [&s](size_t) -> const System& { return s; };
  Sweep::Run(same, row, st, warm_up);
  State start[kChunks];
  size_t start_row[kChunks];
  std::copy(st, st + kChunks, start);
  std::copy(row, row + kChunks, start_row);
  const size_t common = each;  // rows left after the warm-up: each, and more for the last piece
  Sweep::Run(same, row, st, common);
  RunOne<Sweep>(s, row[kChunks - 1], st[kChunks - 1], rows - first[kChunks - 1] - common);
  for (size_t c = 1; c < kChunks; ++c) {
    if (SameBits(st[c - 1], start[c])) continue;
    st[c] = st[c - 1];  // piece c again, from the state piece c-1 ended with
    RunOne<Sweep>(s, start_row[c], st[c], first[c + 1] - first[c]);
  }
  state = st[kChunks - 1];
}

// One sweep of every system: the long ones in pieces, the others side by side while both have
// rows.
template <class Sweep>
void RunSweep(const System* system, size_t count, typename Sweep::State* state,
              size_t warm_up) {
  const size_t chunked = ChunkedSweepNodes(warm_up);
  const System* plain[2];
  size_t plain_count = 0;
  typename Sweep::State* plain_state[2];
  for (size_t i = 0; i < count; ++i) {
    if (system[i].m >= chunked) {
      RunChunked<Sweep>(system[i], state[i], warm_up);
    } else {
      plain_state[plain_count] = &state[i];
      plain[plain_count++] = &system[i];
    }
  }
  size_t done = 0;
  if (plain_count == 2) {
    const auto both = [&plain](size_t k) -> const System& { return *plain[k]; };
    size_t row[2] = {Sweep::Row(*plain[0], 0), Sweep::Row(*plain[1], 0)};
    typename Sweep::State st[2] = {*plain_state[0], *plain_state[1]};
    done = std::min(Sweep::Rows(*plain[0]), Sweep::Rows(*plain[1]));
    Sweep::Run(both, row, st, done);
    *plain_state[0] = st[0];
    *plain_state[1] = st[1];
  }
  for (size_t i = 0; i < plain_count; ++i) {
    RunOne<Sweep>(*plain[i], Sweep::Row(*plain[i], done), *plain_state[i],
                  Sweep::Rows(*plain[i]) - done);
  }
}

}  // namespace

size_t ChunkedSweepNodes(size_t warm_up) { return 8 * std::max<size_t>(warm_up, 1); }

// Divided differences for the 2- and 3-node cases (a line, a parabola).
void EnvelopeSpline::Prepare() {
  DividedDifferences(t_.data(), y_.data(), inv_dx_, dd_, t_.size());
}

void FitPair(EnvelopeSpline& a, EnvelopeSpline& b, size_t warm_up) {
  System system[2];
  size_t count = 0;  // the systems of 4 or more nodes; 2 and 3 need only divided differences
  for (EnvelopeSpline* e : {&a, &b}) {
    assert(e->t_.size() == e->y_.size() && e->t_.size() >= 2);
    e->Prepare();
    if (e->t_.size() < 4) continue;
    system[count++] = {e->t_.size(), e->t_.data(), e->dd_, e->inv_dx_, e->diag_,
                       e->rhs_,      e->slope_,    e->c1_, e->c2_};
  }
  warm_up = std::max<size_t>(warm_up, 1);
  Elimination eliminated[2];
  double slope[2];
  for (size_t i = 0; i < count; ++i) eliminated[i] = FirstRows(system[i]);
  RunSweep<EliminationSweep>(system, count, eliminated, warm_up);
  for (size_t i = 0; i < count; ++i) {
    LastRow(system[i], eliminated[i]);
    slope[i] = LastSlope(system[i]);
  }
  RunSweep<SubstitutionSweep>(system, count, slope, warm_up);
  for (size_t i = 0; i < count; ++i) FirstPiece(system[i], slope[i]);
}

SplineView EnvelopeSpline::view() const {
  return {t_.size(), t_.data(), y_.data(), dd_, c1_, c2_, slope_};
}

void EnvelopeSpline::Evaluate(Eigen::Index n, double* out) const { SimdEvaluate(view(), n, out); }

void EnvelopeSpline::EvaluateSift(Eigen::Index n, const double* lower, const double* h,
                                  double* next) const {
  SimdEvaluateSift(view(), n, lower, h, next);
}

}  // namespace gyrodrift::decomposition::internal
