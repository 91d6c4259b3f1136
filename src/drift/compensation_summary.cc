#include "gyrodrift/drift/compensation_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/records.h"

namespace gyrodrift::drift {
namespace {

double RmsAboutMean(const Eigen::Ref<const Eigen::VectorXd>& x) {
  return std::sqrt((x.array() - x.mean()).square().mean());
}

// A figure of the table: %.6g, "n/a" for NaN (a slow variation not measured).
std::string Cell(double v) {
  if (std::isnan(v)) return "n/a";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

}  // namespace

Eigen::VectorXd BlockMeans(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index block) {
  block = std::max<Eigen::Index>(1, block);
  const Eigen::Index blocks = std::max<Eigen::Index>(1, x.size() / block);
  const Eigen::Index length = std::min(block, x.size());
  Eigen::VectorXd out(blocks);
  for (Eigen::Index b = 0; b < blocks; ++b) out[b] = x.segment(b * length, length).mean();
  return out;
}

SignalSummary Summarise(const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index block,
                        const std::vector<bool>& logged) {
  CheckLogged(logged, x.size());
  RequireFiniteLogged("signal", x, logged, 1);
  block = std::max<Eigen::Index>(1, block);
  SignalSummary s;
  if (CountLogged(logged, x.size()) == x.size()) {  // every row logged: the same bits as no mask
    s.mean = x.mean();
    s.std = RmsAboutMean(x);
    s.rms = std::sqrt(x.squaredNorm() / static_cast<double>(x.size()));
    s.blocks = x.size() / block;
    s.slow = s.blocks >= 2 ? RmsAboutMean(BlockMeans(x, block))
                           : std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  const Eigen::VectorXd kept = LoggedRows(x, logged);
  s.mean = kept.mean();
  s.std = RmsAboutMean(kept);
  s.rms = std::sqrt(kept.squaredNorm() / static_cast<double>(kept.size()));
  // Blocks of the time grid (a last partial one dropped), each the mean of its logged samples; a
  // block with none is left out.
  std::vector<double> means;
  for (Eigen::Index b = 0; b + 1 <= x.size() / block; ++b) {
    double sum = 0.0;
    Eigen::Index count = 0;
    for (Eigen::Index i = b * block; i < (b + 1) * block; ++i) {
      if (!logged[static_cast<size_t>(i)]) continue;
      sum += x[i];
      ++count;
    }
    if (count > 0) means.push_back(sum / static_cast<double>(count));
  }
  s.blocks = static_cast<Eigen::Index>(means.size());
  s.slow = s.blocks >= 2 ? RmsAboutMean(Eigen::Map<const Eigen::VectorXd>(means.data(), s.blocks))
                         : std::numeric_limits<double>::quiet_NaN();
  return s;
}

CompensationSummary SummariseCompensation(const Eigen::Ref<const Eigen::VectorXd>& y,
                                          const Eigen::Ref<const Eigen::VectorXd>& compensated,
                                          double rate_hz, double block_s,
                                          const std::vector<bool>& logged) {
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e6);
  RequireInRange("block_s", block_s, 1e-6, 1e9);
  CheckLogged(logged, y.size());
  RequireFiniteLogged("output", y, logged, 1);
  RequireFiniteLogged("compensated output", compensated, logged, 1);
  if (compensated.size() != y.size()) {
    throw DataError("compensation summary: the output has " + std::to_string(y.size()) +
                    " samples, the compensated output " + std::to_string(compensated.size()));
  }
  CompensationSummary s;
  s.samples = CountLogged(logged, y.size());
  s.block_s = block_s;
  s.block = std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::llround(block_s * rate_hz)));
  s.before = Summarise(y, s.block, logged);
  s.after = Summarise(compensated, s.block, logged);
  s.blocks = s.before.blocks;
  return s;
}

std::string CompensationSummary::Table(const std::string& target, const std::string& unit) const {
  char line[256];
  // The names are the user's, of any length: not through the fixed buffer.
  std::string out = target + (unit.empty() ? "" : " (" + unit + ")") + ", " +
                    std::to_string(samples) + " samples:\n";
  std::snprintf(line, sizeof(line), "  %-16s %14s %14s\n", "", "before", "after");
  out += line;
  auto row = [&](const char* name, double b, double a, const std::string& note) {
    std::snprintf(line, sizeof(line), "  %-16s %14s %14s%s\n", name, Cell(b).c_str(),
                  Cell(a).c_str(), note.c_str());
    out += line;
  };
  row("mean", before.mean, after.mean, "");
  row("RMS", before.rms, after.rms, "  (about zero)");
  row("std", before.std, after.std, "  (about the mean)");
  char note[160];
  if (blocks >= 2) {
    std::snprintf(note, sizeof(note), "  (RMS about their mean of %lld means of %g-s blocks)",
                  static_cast<long long>(blocks), block_s);
  } else {
    std::snprintf(note, sizeof(note), "  (not measured: the log is shorter than 2 blocks of %g s)",
                  block_s);
  }
  row("slow variation", before.slow, after.slow, note);
  // What a user without the truth can see of a compensation that made the gyro worse [choice,
  // docs/drift.md 1.5: on family units 700-739 it marked 21 of the 26 compensations worse than
  // doing nothing, and 11 of the 214 better].
  constexpr double kRiseWarned = 1.25;
  if (after.slow > kRiseWarned * before.slow) {
    char rise[64];
    if (before.slow > 0.0) {
      std::snprintf(rise, sizeof(rise), "by %.3g %%", 100.0 * (after.slow / before.slow - 1.0));
    } else {
      std::snprintf(rise, sizeof(rise), "from 0 to %s", Cell(after.slow).c_str());
    }
    out += std::string("  warning: compensation raised the slow variation ") + rise +
           ": on this log the model does worse than none at the drift's time scale (see its "
           "calibration's warnings)\n";
  }
  return out;
}

}  // namespace gyrodrift::drift
