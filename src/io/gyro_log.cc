#include "gyrodrift/io/gyro_log.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>
#include <utility>
#include <vector>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/statistics.h"

namespace gyrodrift::io {
namespace {

constexpr gyrodrift::internal::EnumNames<GapPolicy, 4> kGapPolicies{{
    {GapPolicy::kError, "error"},
    {GapPolicy::kInterpolate, "interpolate"},
    {GapPolicy::kSplit, "split"},
    {GapPolicy::kCarry, "carry"},
}};

}  // namespace

std::string_view ToString(GapPolicy policy) {
  return gyrodrift::internal::EnumName(policy, kGapPolicies);
}

GapPolicy GapPolicyFromString(std::string_view text) {
  return gyrodrift::internal::EnumFromName(text, "gaps", kGapPolicies);
}

namespace {

// A gap: a step of this many median steps or more, so at least one sample is missing.
constexpr double kGapSteps = 1.5;
// The most samples gaps are filled with in all (800 MB a column): 10,000 rows with a gap of 1e5
// samples after every third asked for 3e8 and ended in "out of memory".
constexpr double kMostFilledSamples = 1e8;

// The table's time axis (CsvReadOptions::time_axis) when every step of it is counted and > 0:
// what the checks and the notes can use instead of the time_s column.
const TimeAxis* RegularAxis(const CsvTable& table) {
  const TimeAxis* axis = table.time_axis();
  return axis && axis->complete() && axis->increasing() && axis->rows() >= 2 ? axis : nullptr;
}

// The clock's step: the mean of the steps within 1 % of the median step. Large time stamps (epoch
// seconds) round every step to a representable difference, so the median step of a 100 Hz log
// stamped near 1.76e9 s is 0.0099999905 s (100.0000954 Hz), while the mean of such steps carries
// no such rounding. A step further off is a gap, a late, an extra or a missed sample, which the
// median ignores and the mean would not. The median stands where the two agree to 1e-9, so the
// rate of every log whose stamps round only in their last bits (a decimal clock) is what it was.
double ClockStep(const CsvTable& table, const TimeAxis* axis, double median) {
  const double lo = 0.99 * median, hi = 1.01 * median;
  double mean = 0.0;
  if (axis) {
    mean = axis->MeanStepWithin(lo, hi);
  } else {
    const Eigen::VectorXd& t = table.ColumnRef("time_s");
    long double sum = 0.0L;
    Eigen::Index count = 0;
    for (Eigen::Index i = 0; i + 1 < t.size(); ++i) {
      const double step = t[i + 1] - t[i];
      if (step >= lo && step <= hi) {
        sum += step;
        ++count;
      }
    }
    mean = static_cast<double>(sum / static_cast<long double>(count));
  }
  // No step within 1 % (an even count whose middle two straddle it): the median.
  return std::abs(mean / median - 1.0) > 1e-9 ? mean : median;
}

// Whether the caller's user sets the log options as flags (--gaps) rather than manifest keys.
bool SpeltAsFlags(const LogOptions& options) { return options.gaps_name.rfind("--", 0) == 0; }

}  // namespace

std::string SpellGaps(const LogOptions& options, GapPolicy policy) {
  if (SpeltAsFlags(options)) {
    return options.gaps_name + " " + std::string(ToString(policy));
  }
  return fmt::format("{} = '{}'", options.gaps_name, ToString(policy));
}

namespace {

// "note: 3 damaged lines skipped (--bad-lines skip): lines 3, 5, 7", the first 10 lines named.
std::string SkippedNote(const CsvTable& table, const LogOptions& options) {
  const std::vector<Eigen::Index>& lines = table.skipped_lines();
  if (lines.empty()) return "";
  std::string named;
  for (size_t i = 0; i < lines.size() && i < 10; ++i) {
    named += fmt::format("{}{}", i == 0 ? "" : ", ", lines[i]);
  }
  if (lines.size() > 10) named += fmt::format(" and {} more", lines.size() - 10);
  return fmt::format("note: {}: {} damaged line{} skipped ({}): line{} {}", table.source(),
                     lines.size(), lines.size() == 1 ? "" : "s",
                     SpeltAsFlags(options) ? "--bad-lines skip" : "bad_lines = 'skip'",
                     lines.size() == 1 ? "" : "s",
                     named);
}

CsvTable ReadLogRows(const std::string& path, const LogOptions& options, std::string* gap_note,
                     std::vector<Eigen::Index>* record_starts,
                     const std::vector<std::string>& columns, std::vector<bool>* logged);

}  // namespace

bool IsUlogFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[7] = {};
  return in.read(magic, sizeof magic) &&
         std::string_view(magic, sizeof magic) == std::string_view("ULog\x01\x12\x35", 7);
}

CsvTable ReadLog(const std::string& path, const LogOptions& options, std::string* gap_note,
                 std::vector<Eigen::Index>* record_starts, const std::vector<std::string>& columns,
                 std::vector<bool>* logged) {
  CsvTable table = ReadLogRows(path, options, gap_note, record_starts, columns, logged);
  const std::string skipped = SkippedNote(table, options);
  if (gap_note && !skipped.empty()) {
    *gap_note = gap_note->empty() ? skipped : skipped + "\n" + *gap_note;
  }
  return table;
}

namespace {

// Refuses a gap policy the caller cannot honour.
void RequireHonoured(const std::string& path, const LogOptions& options, bool takes_records,
                     bool takes_mask) {
  auto spell = [&options](GapPolicy p) { return SpellGaps(options, p); };
  if (options.gaps == GapPolicy::kSplit && !takes_records) {
    throw UsageError(path + ": " + spell(options.gaps) +
                     " needs a caller that takes several records (a thermal model's fit or "
                     "compensation); this one needs one uniform record: use " +
                     spell(GapPolicy::kInterpolate) + ", or split the file");
  }
  if (options.gaps == GapPolicy::kCarry && !takes_mask) {
    throw UsageError(path + ": " + spell(options.gaps) +
                     " needs a caller that fits and scores on the logged rows only (a thermal "
                     "model's fit or compensation); this one would use the made-up rows as "
                     "data: use " + spell(GapPolicy::kInterpolate) + " to say so");
  }
}

// A caller that names its columns needs of time_s only ReadLogRows' checks and the notes: its
// steps are gathered while reading (8 bytes a row less), and it is read whole (again) only when
// they show a fault or a gap, for the checks to name it as before.
CsvTable ReadColumns(const std::string& path, CsvReadOptions read) {
  if (read.columns.empty()) return CsvTable::Read(path, read);
  read.time_axis = "time_s";
  CsvTable table = CsvTable::Read(path, read);
  const TimeAxis* axis = RegularAxis(table);
  if (!table.time_axis() ||
      (axis && (axis->rows() < 3 || axis->LargestStep() < kGapSteps * axis->MedianStep()))) {
    return table;
  }
  read.time_axis.clear();
  read.columns.push_back("time_s");
  return CsvTable::Read(path, read);
}

// The log's table: a CSV file under the read settings, or a ULog's series rendered as `convert`
// writes it and parsed back (so a ULog gives the numbers its converted CSV gives, to the bit).
// The ULog's damage skipped is added to *notes as warnings.
CsvTable ReadTable(const std::string& path, const LogOptions& options,
                   const std::vector<std::string>& columns, std::string* notes) {
  CsvReadOptions read{.delimiter = options.delimiter,
                      .columns = columns,
                      .names = options.names,
                      .skip_rows = options.skip_rows,
                      .bad_lines = options.bad_lines};
  if (!IsUlogFile(path)) return ReadColumns(path, read);
  if (!columns.empty()) read.columns.push_back("time_s");
  RequireInRange("ulog_instance", options.ulog_instance, 0, kMaxUlogInstance);
  if (!options.names.empty() || options.skip_rows != 0) {
    throw UsageError(fmt::format(
        "{} is a ULog: {} apply to CSV logs only", path,
        SpeltAsFlags(options) ? "--no-header, --columns and --skip-rows"
                              : "names and skip_rows"));
  }
  const Ulog log = ReadUlog(path, {options.ulog.topic});
  for (const std::string& w : log.warnings) {
    if (notes) *notes += (notes->empty() ? "" : "\n") + fmt::format("warning: {}: {}", path, w);
  }
  const UlogSeries& series =
      *SeriesWithSamples(log, path, options.ulog.topic, options.ulog_instance).front();
  read.delimiter = Delimiter::kComma;
  read.names.clear();
  std::istringstream text(RenderCsv(UlogColumns(series, options.ulog)));
  return CsvTable::Read(text, path, read);
}

// Refuses a time_s that repeats or goes backwards, naming the row.
void RequireIncreasing(const std::string& path, const Eigen::VectorXd& t) {
  for (Eigen::Index i = 1; i < t.size(); ++i) {
    if (t[i] > t[i - 1]) continue;
    throw DataError(fmt::format(
        "{}: time_s {} at data row {} ({:g} s after {:g} s): time stamps must increase (sort "
        "the log or split it where the clock jumped)",
        path, t[i] == t[i - 1] ? "repeats" : "goes backwards", i + 1, t[i], t[i - 1]));
  }
}

// The gaps of time_s: a step of kGapSteps median steps or more, so at least one sample is missing.
// Each as (the row before it, the samples missing); with split, the records' starts instead.
struct Gaps {
  double median = 0.0;
  std::vector<std::pair<Eigen::Index, int>> insert;
  long missing = 0;
};

// `record_starts` and `takes_logged`: whether the caller takes records (split) and logged rows
// (carry), so that a refusal offers only the ways out it has.
Gaps FindGaps(const std::string& path, const Eigen::VectorXd& t, const LogOptions& options,
              std::vector<Eigen::Index>* record_starts, bool takes_logged) {
  auto spell = [&options](GapPolicy p) { return SpellGaps(options, p); };
  // Only a caller that takes records (record_starts) can split the log itself.
  const std::string split = record_starts
                                ? "split the log at its gaps (" + spell(GapPolicy::kSplit) + ")"
                                : std::string("split the file at its gaps into logs of their own");
  Gaps gaps{.median = MedianStep(t), .insert = {}, .missing = 0};
  for (Eigen::Index i = 0; i + 1 < t.size(); ++i) {
    const double step = t[i + 1] - t[i];
    if (!(step >= kGapSteps * gaps.median)) continue;
    const double samples = std::round(step / gaps.median) - 1.0;
    gaps.missing += static_cast<long>(samples);
    if (options.gaps == GapPolicy::kSplit) {
      record_starts->push_back(i + 1);
      continue;
    }
    // A gap of more than 1e7 samples or 10 times the log is a clock jump, not lost samples.
    if (options.gaps == GapPolicy::kError || samples > 1e7 ||
        samples > 10.0 * static_cast<double>(t.size())) {
      throw DataError(fmt::format(
          "{}: time_s jumps by {:g} s before data row {} ({:g} missing samples at the median step "
          "{:g} s): {}",
          path, step, i + 2, samples, gaps.median,
          options.gaps == GapPolicy::kError
              ? fmt::format(
                    "fill gaps by linear interpolation ({}{}){}", spell(GapPolicy::kInterpolate),
                    takes_logged
                        ? ", or " + spell(GapPolicy::kCarry) + " to fit on the logged rows only"
                        : std::string(),
                    record_starts ? fmt::format(" or split the log into records at its "
                                                "gaps ({})",
                                                spell(GapPolicy::kSplit))
                                  : std::string())
              : "too long to fill by interpolation: " + split));
    }
    gaps.insert.push_back({i, static_cast<int>(samples)});
  }
  const auto filled = static_cast<double>(gaps.missing);
  if (options.gaps != GapPolicy::kSplit && filled > kMostFilledSamples) {
    throw DataError(fmt::format(
        "{}: time_s has {} gaps that would be filled with {:g} samples (at most {:g}): {}", path,
        gaps.insert.size(), filled, kMostFilledSamples, split));
  }
  return gaps;
}

// What the gaps' handling did, for the user; with interpolate a warning when most rows are made
// up. Empty when there is nothing to say.
std::string GapNote(const Gaps& gaps, const LogOptions& options, Eigen::Index logged_rows,
                    size_t records) {
  auto spell = [&options](GapPolicy p) { return SpellGaps(options, p); };
  auto plural = [](size_t n) { return n == 1 ? "" : "s"; };
  if (options.gaps == GapPolicy::kSplit) {
    if (records <= 1) return "";
    return fmt::format(
        "note: time_s has {} gap{} (median step {:g} s, {} samples missing): the log is split "
        "into {} records, and the thermal model's lag states restart after each gap ({})",
        records - 1, plural(records - 1), gaps.median, gaps.missing, records,
        spell(options.gaps));
  }
  if (gaps.insert.empty()) return "";
  const long rows = static_cast<long>(logged_rows) + gaps.missing;
  const double made_up = static_cast<double>(gaps.missing) / static_cast<double>(rows);
  const size_t count = gaps.insert.size();
  if (options.gaps == GapPolicy::kCarry) {
    return fmt::format(
        "note: time_s has {} gap{} (median step {:g} s): {} of {} rows ({:.1f} %) filled by "
        "linear interpolation for the thermal states to run across; fits, scores and reports use "
        "the {} logged rows only ({})",
        count, plural(count), gaps.median, gaps.missing, rows, 100.0 * made_up, logged_rows,
        spell(options.gaps));
  }
  if (made_up > kMostlyMadeUpShare) {
    return fmt::format(
        "warning: time_s has {} gap{} (median step {:g} s): {} of {} rows ({:.1f} %) are made up "
        "by linear interpolation ({}), and they count as data wherever the rows are used; {} "
        "fits, scores and reports on the {} logged rows only",
        count, plural(count), gaps.median, gaps.missing, rows, 100.0 * made_up,
        spell(options.gaps), spell(GapPolicy::kCarry), logged_rows);
  }
  return fmt::format(
      "note: time_s has {} gap{} (median step {:g} s): {} samples filled by linear "
      "interpolation ({})",
      count, plural(count), gaps.median, gaps.missing, spell(options.gaps));
}

// One flag per row after filling: true where the row was logged.
std::vector<bool> LoggedMask(const Gaps& gaps, Eigen::Index logged_rows) {
  std::vector<bool> logged;
  logged.reserve(static_cast<size_t>(logged_rows + gaps.missing));
  size_t next = 0;
  for (Eigen::Index i = 0; i < logged_rows; ++i) {
    logged.push_back(true);
    if (next < gaps.insert.size() && gaps.insert[next].first == i) {
      logged.insert(logged.end(), static_cast<size_t>(gaps.insert[next].second), false);
      ++next;
    }
  }
  return logged;
}

CsvTable ReadLogRows(const std::string& path, const LogOptions& options, std::string* gap_note,
                     std::vector<Eigen::Index>* record_starts,
                     const std::vector<std::string>& columns, std::vector<bool>* logged) {
  if (gap_note) gap_note->clear();
  if (record_starts) record_starts->clear();
  if (logged) logged->clear();
  RequireHonoured(path, options, record_starts != nullptr, logged != nullptr);
  std::string ulog_note;
  CsvTable table = ReadTable(path, options, columns, &ulog_note);
  if (gap_note) *gap_note = ulog_note;
  if (!table.HasColumn("time_s")) return table;
  const Eigen::VectorXd* time = nullptr;
  try {
    time = &table.ColumnRef("time_s");
  } catch (const Error&) {
    return table;  // unreadable: refused where the rate is read from it (ResolveSampleRate)
  }
  const Eigen::VectorXd& t = *time;
  RequireIncreasing(path, t);
  if (t.size() < 3) return table;
  const Gaps gaps = FindGaps(path, t, options, record_starts, logged != nullptr);
  const std::string note = GapNote(gaps, options, t.size(),
                                   record_starts ? record_starts->size() + 1 : 1);
  if (gap_note && !note.empty()) *gap_note += (gap_note->empty() ? "" : "\n") + note;
  if (options.gaps == GapPolicy::kSplit || gaps.insert.empty()) return table;
  if (logged) *logged = LoggedMask(gaps, t.size());
  return table.WithInterpolatedRows(gaps.insert);
}

}  // namespace


double ResolveSampleRate(const CsvTable& table, double given, std::string* how) {
  if (given > 0.0) {
    *how = "given";
    return given;
  }
  if (!table.HasColumn("time_s") || table.rows() < 2) {
    *how = "default";
    return 1.0;
  }
  const TimeAxis* axis = RegularAxis(table);
  const double median = axis ? axis->MedianStep() : MedianStep(table.ColumnRef("time_s"));
  if (!(median > 0.0)) {
    throw DataError(table.source() + ": column 'time_s' has a median step of " +
                    FormatValue(median) +
                    " s: it must increase to give the sample rate (or give rate_hz)");
  }
  *how = "time_s";
  const double rate = 1.0 / ClockStep(table, axis, median);
  if (!(rate >= 1e-9 && rate <= 1e6)) {
    throw DataError(table.source() + ": column 'time_s' has a median step of " +
                    FormatValue(median) + " s, a sample rate of " + FormatValue(rate) +
                    " Hz outside [1e-09, 1e+06] Hz (seconds expected; or give rate_hz)");
  }
  return rate;
}

void RequireSameSampleRate(const std::string& first, double first_hz, const std::string& log,
                           double rate_hz) {
  if (std::abs(rate_hz / first_hz - 1.0) <= 0.01) return;
  throw DataError(fmt::format(
      "{} is sampled at {:g} Hz, {} at {:g} Hz: calibration logs fitted together need one sample "
      "rate (resample one, or pass the rate if the time stamps are wrong)",
      first, first_hz, log, rate_hz));
}

namespace {

std::string NonUniformNote(long off, Eigen::Index steps, double median, double shortest,
                           Eigen::Index shortest_row) {
  if (off == 0) return "";
  return fmt::format(
      "note: time_s is not uniform: {} of {} steps are shorter than half the median step {:g} s "
      "(shortest {:g} s, before data row {}); the models and the Allan analysis treat the "
      "samples as equally spaced",
      off, steps, median, shortest, shortest_row);
}

}  // namespace

std::string NonUniformTimeNote(const CsvTable& table) {
  if (!table.HasColumn("time_s") || table.rows() < 3) return "";
  if (const TimeAxis* axis = RegularAxis(table)) {
    const double median = axis->MedianStep();
    const TimeAxis::Step shortest = axis->Shortest();
    return NonUniformNote(axis->StepsBelow(0.5 * median), table.rows() - 1, median,
                          shortest.value, shortest.first + 2);
  }
  const Eigen::VectorXd* time = nullptr;
  try {
    time = &table.ColumnRef("time_s");
  } catch (const Error&) {
    return "";  // a note never fails a command; where time_s is needed it is read and refused
  }
  const Eigen::VectorXd& t = *time;
  const double median = MedianStep(t);  // > 0: ReadLog refused a time_s that does not increase
  long off = 0;
  double shortest = t[1] - t[0];
  Eigen::Index shortest_row = 2;  // 1-based data row of the sample after the step
  for (Eigen::Index i = 0; i + 1 < t.size(); ++i) {
    const double step = t[i + 1] - t[i];
    if (step < 0.5 * median) ++off;  // a gap (>= 1.5 median) was refused, filled or split
    if (step < shortest) {
      shortest = step;
      shortest_row = i + 2;
    }
  }
  return NonUniformNote(off, t.size() - 1, median, shortest, shortest_row);
}


}  // namespace gyrodrift::io
