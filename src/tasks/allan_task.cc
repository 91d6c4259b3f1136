#include "gyrodrift/tasks/allan_task.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::tasks {
namespace {

namespace al = gyrodrift::allan;

// Arc-seconds per microradian: Q is also given in arcsec, the unit of many datasheets.
constexpr double kArcsecPerUrad = 0.206264806247;

void ParseTaus(const std::string& text, al::AllanOptions* o) {
  if (text == "all" || text == "octave" || text == "decade") {
    o->grid = al::TauGridFromString(text);
    return;
  }
  o->grid = al::TauGrid::kList;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    const bool blank_tail =
        end != item.c_str() && std::string(end).find_first_not_of(" \t") == std::string::npos;
    if (!blank_tail || !(v > 0.0) || !std::isfinite(v)) {
      ThrowOption(
          "taus", text,
          "all, octave, decade or a comma-separated list of positive taus in s (bad item '" + item +
              "')");
    }
    o->tau_list_s.push_back(v);
  }
  if (o->tau_list_s.empty()) ThrowOption("taus", text, "all, octave, decade or a list of taus");
}

// Averages span whole samples: a tau between two is not silently moved to the nearer one.
void RequireWholeSamples(const std::vector<double>& taus, double rate_hz) {
  for (double tau : taus) {
    const double m = tau * rate_hz;
    // Absolute in samples, loose enough for decimal taus such as 0.1 s at 10 Hz, plus the
    // rate's own uncertainty when time_s gave it (epoch stamps of a 200-s log at 100 Hz:
    // about 1e-9 of the rate); half a sample would pass only past 5e7 samples.
    if (m < 1.0 - 1e-9 || std::abs(m - std::round(m)) > 1e-6 + 1e-8 * m) {
      ThrowOption("taus", fmt::format("{:g}", tau),
                  fmt::format("a whole number of sample periods at {:g} Hz (nearest: {:g} s)",
                              rate_hz, std::max(1.0, std::round(m)) / rate_hz));
    }
  }
}

// The noise terms need an Allan-variance curve.
bool AllanCurve(al::Deviation d) {
  return d == al::Deviation::kAdev || d == al::Deviation::kOadev || d == al::Deviation::kTotdev;
}

nlohmann::json TermJson(const al::NoiseTerm& t, const char* unit) {
  return {{"unit", unit},
          {"identified", t.identified},
          {"value", t.value},
          {"sigma", t.sigma},
          {"tau_lo_s", t.tau_lo_s},
          {"tau_hi_s", t.tau_hi_s},
          {"slope_reading", t.slope_reading},
          {"slope_tau_s", t.slope_tau_s},
          {"evidence_chi2", t.evidence_chi2}};
}

nlohmann::json PointsRecord(const al::AllanResult& r) {
  nlohmann::json points = nlohmann::json::array();
  for (const auto& p : r.points) {
    points.push_back({{"tau_s", p.tau_s},
                      {"m", p.m},
                      {"dev", p.dev},
                      {"dev_lo", p.dev_lo},
                      {"dev_hi", p.dev_hi},
                      {"n_terms", p.n_terms},
                      {"edf", p.edf},
                      {"alpha", p.alpha},
                      {"noise_type", al::NoiseTypeName(p.alpha)},
                      {"alpha_identified", p.alpha_identified}});
  }
  return points;
}

}  // namespace

al::AllanOptions AllanSettings::Options() const {
  // Beyond this range the averages under- or overflow (1e308 Hz gave all-zero deviations).
  RequireInRange("rate_hz", rate_hz, 1e-9, 1e9);
  al::AllanOptions o;
  // A refusal names the setting the user gave (type, taus), not the library's field.
  ValidateAsSettings({{"data_type", "type"}, {"deviation", "dev"}, {"tau_list_s", "taus"}}, [&] {
    o.rate_hz = rate_hz;
    o.data_type = al::DataTypeFromString(type);
    o.deviation = al::DeviationFromString(dev);
    o.units = al::RateUnitFromString(units);
    o.confidence = confidence;
    if (tau_list_s.empty()) {
      ParseTaus(taus, &o);
    } else {
      o.grid = al::TauGrid::kList;
      o.tau_list_s = tau_list_s;
    }
    RequireWholeSamples(o.tau_list_s, rate_hz);
    o.Validate();
  });
  return o;
}

al::NoiseFitOptions AllanSettings::FitOptions() const {
  const al::NoiseFitOptions o{.tau_min_s = fit_tau_min_s, .tau_max_s = fit_tau_max_s};
  ValidateAsSettings({{"tau_min_s", "fit_tau_min"}, {"tau_max_s", "fit_tau_max"}},
                     [&] { o.Validate(); });
  return o;
}

Execution AllanSettings::MakeExecution() const {
  const Execution execution{.threads = threads};
  execution.Validate();
  return execution;
}

void AllanSettings::Validate() const {
  Options();
  MakeExecution();
  FitOptions();
}

Eigen::VectorXd JoinRecords(const Eigen::VectorXd& data,
                            const std::vector<Eigen::Index>& record_starts,
                            std::vector<bool>* logged) {
  if (!logged->empty()) {
    throw UsageError(
        "logged and record_starts: give one (a record with gaps on its time grid, "
        "or records to join)");
  }
  Eigen::Index previous = 0;
  for (size_t r = 0; r < record_starts.size(); ++r) {
    if (record_starts[r] <= previous || record_starts[r] >= data.size()) {
      throw DataError(
          fmt::format("record_starts[{}] = {}: record starts must increase within 1..{}", r,
                      record_starts[r], data.size() - 1));
    }
    previous = record_starts[r];
  }
  Eigen::VectorXd joined(data.size() + static_cast<Eigen::Index>(record_starts.size()));
  logged->assign(static_cast<size_t>(joined.size()), true);
  Eigen::Index from = 0, to = 0;
  for (size_t r = 0; r <= record_starts.size(); ++r) {
    const Eigen::Index end = r < record_starts.size() ? record_starts[r] : data.size();
    joined.segment(to, end - from) = data.segment(from, end - from);
    to += end - from;
    if (r < record_starts.size()) {
      joined[to] = 0.0;  // never read: a break between records
      (*logged)[static_cast<size_t>(to++)] = false;
    }
    from = end;
  }
  return joined;
}

AllanRun RunAllan(Eigen::VectorXd data, const std::vector<bool>& logged,
                  const AllanSettings& settings, std::string_view signal_name) {
  const al::AllanOptions o = settings.Options();
  // One sample has no difference to take (it would read as "constant" below).
  if (data.size() < 2) {
    throw DataError(fmt::format("{} has {} sample{}: an Allan deviation needs at least 2",
                                signal_name, data.size(), data.size() == 1 ? "" : "s"));
  }
  // Constant where it was logged (the breaks and made-up rows hold anything), found without a
  // copy of the record: RequireVaryingSignal of the first logged sample alone names its value.
  const char* why = "its Allan deviation is zero at every tau (a logging fault?)";
  if (logged.empty()) {
    RequireVaryingSignal(signal_name, data, why);
  } else {
    Eigen::Index first = -1;
    bool varies = false;
    for (Eigen::Index i = 0; i < data.size() && !varies; ++i) {
      if (!logged[static_cast<size_t>(i)]) continue;
      if (first < 0) first = i;
      varies = data[i] != data[first];
    }
    if (first >= 0 && !varies) RequireVaryingSignal(signal_name, data.segment(first, 1), why);
  }
  const Execution execution = settings.MakeExecution();
  const al::NoiseFitOptions fit_options = settings.FitOptions();
  const bool allan_curve = AllanCurve(o.deviation);
  // The record's last use hands it over: the phase is built in its storage (no second copy).
  auto compute = [&](const al::AllanOptions& options, bool last_use) {
    if (!logged.empty()) return al::ComputeWithGaps(data, logged, options, execution);
    return last_use ? al::Compute(std::move(data), options, execution)
                    : al::Compute(data, options, execution);
  };
  AllanRun run;
  ValidateAsSettings({{"deviation", "dev"}, {"data_type", "type"}},
                     [&] { run.curve = compute(o, allan_curve); });
  run.dev_unit = al::ToString(o.units) + (o.deviation == al::Deviation::kTdev ? "*s" : "");
  run.fit_source = al::ToString(o.deviation);
  try {
    if (allan_curve) {
      run.terms = al::IdentifyNoise(run.curve, fit_options);
    } else {
      al::AllanOptions oa = o;
      oa.deviation = al::Deviation::kOadev;
      run.fit_source = "oadev";
      run.terms = al::IdentifyNoise(compute(oa, true), fit_options);
    }
  } catch (const DataError& e) {
    run.fit_error = e.what();  // too few points to fit: the deviations are still the result
  }
  return run;
}

nlohmann::json NoiseTermsRecord(const al::NoiseTerms& t) {
  return {{"critical_chi2", t.critical_chi2},
          {"points_used", t.points_used},
          {"tau_min_s", t.tau_min_s},
          {"tau_max_s", t.tau_max_s},
          {"chi2_per_dof", t.chi2_per_dof},
          {"min_dev_dph", t.min_dev_dph},
          {"min_dev_tau_s", t.min_dev_tau_s},
          {"Q", TermJson(t.q_urad, "urad")},
          {"Q_arcsec", t.q_urad.value * kArcsecPerUrad},
          {"N", TermJson(t.n_dpsh, "deg/sqrt(h)")},
          {"B", TermJson(t.b_dph, "deg/h")},
          {"K", TermJson(t.k_dphpsh, "deg/h/sqrt(h)")},
          {"R", TermJson(t.r_dphph, "deg/h/h")},
          {"summary", t.Summary()},
          {"note", t.note}};
}

nlohmann::json AllanRecord(const AllanRun& run, const AllanSettings& settings,
                           const std::vector<bool>& logged) {
  const al::AllanOptions o = settings.Options();
  const al::NoiseFitOptions fit = settings.FitOptions();
  nlohmann::json record;
  record["options"] = {
      {"rate_hz", o.rate_hz},
      {"tau0_s", o.tau0_s()},
      {"type", al::ToString(o.data_type)},
      {"dev", al::ToString(o.deviation)},
      {"taus", settings.taus},
      {"tau_grid", al::ToString(o.grid)},
      {"tau_list_s", o.tau_list_s},
      {"units", al::ToString(o.units)},
      {"confidence", o.confidence},
      {"threads", settings.threads},
      {"fit_tau_min_s", fit.tau_min_s},
      {"fit_tau_max_s",
       std::isfinite(fit.tau_max_s) ? nlohmann::json(fit.tau_max_s) : nlohmann::json("inf")},
      {"seed", nullptr}};
  record["samples"] = run.curve.n_samples;
  // The analysed grid: with gaps skipped, how many of its samples were logged.
  if (!logged.empty()) {
    record["logged_samples"] = std::count(logged.begin(), logged.end(), true);
    record["gaps_method"] =
        "overlapping estimator over the cluster pairs whose samples are all logged (made-up "
        "samples and record breaks skipped); EDF of a gap-free record with as many terms";
  }
  record["summary"] = run.curve.Summary();
  record["dev_unit"] = run.dev_unit;
  record["edf_method"] =
      "Greenhall & Riley 2003 (TOTDEV: NIST SP 1065 table 7); noise type per tau by lag-1 "
      "autocorrelation, carried forward below 30 points";
  record["points"] = PointsRecord(run.curve);
  if (run.terms) {
    nlohmann::json terms = NoiseTermsRecord(*run.terms);
    terms["source_dev"] = run.fit_source;
    terms["method"] =
        "IEEE 952 model fitted in log variance (weights from the EDF); terms removed steepest "
        "first (R, Q, K, N, B) while a nested chi-square test at the significance level, "
        "corrected for the correlated overlapping points, finds them unnecessary, or while they "
        "stay below 10 % of the model at every tau; uncertainties from the correlated points "
        "(docs/allan.md)";
    record["noise_terms"] = terms;
  } else {
    record["noise_terms"] = {{"error", run.fit_error}};
  }
  return record;
}

}  // namespace gyrodrift::tasks
