// Bindings of the logs people have and the runs they plan: read_log (a gyro log as every command
// reads it), read_ulog, ulog_columns (what `gyrodrift convert` writes) and plan (what
// `gyrodrift plan` writes), as the CLI computes them.
#include "bindings.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/drift/calibration_plan.h"
#include "gyrodrift/io/ulog.h"
#include "gyrodrift/tasks/task_log.h"

namespace gyrodrift::python {
namespace {

// A log's text as str: a damaged log's names need not be UTF-8 (undecodable bytes become U+FFFD,
// where the default conversion raised UnicodeDecodeError).
py::str Text(const std::string& text) {
  PyObject* decoded =
      PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "replace");
  if (!decoded) throw py::error_already_set();
  return py::reinterpret_steal<py::str>(decoded);
}

py::list Texts(const std::vector<std::string>& texts) {
  py::list out;
  for (const std::string& t : texts) out.append(Text(t));
  return out;
}

// One series as a dict: its description, and its samples when decoded (values by field).
py::dict SeriesDict(const io::UlogSeries& s) {
  py::dict d;
  d["topic"] = Text(s.topic);
  d["instance"] = s.instance;
  d["fields"] = Texts(s.fields);
  d["types"] = Texts(s.types);
  d["samples"] = s.samples;
  d["first_us"] = s.first_us;
  d["last_us"] = s.last_us;
  d["decoded"] = s.decoded;
  if (s.decoded) {
    d["timestamp_us"] = py::array_t<std::uint64_t>(static_cast<py::ssize_t>(s.timestamp_us.size()),
                                                   s.timestamp_us.data());
    py::dict values;
    for (const std::string& f : s.fields) {
      const std::vector<double> v = s.Column(f);
      values[Text(f)] = py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
    }
    d["values"] = values;
  }
  return d;
}

// A gyro log as the CLI's fit, compensate, evaluate and allan read it (tasks::ReadTaskLog):
// every column, the gaps filled or split under `gaps`, the rate settled; what the CLI prints as a
// warning before the work is a UserWarning here.
py::dict ReadLog(const std::string& path, const std::string& gaps, std::optional<double> rate_hz,
                 const std::string& delimiter, const std::vector<std::string>& names, int skip_rows,
                 const std::string& bad_lines, const std::string& ulog_topic, int ulog_instance,
                 const std::string& ulog_units) {
  // The range io::ResolveSampleRate accepts from a time_s column.
  if (rate_hz) RequireInRange("rate_hz", *rate_hz, 1e-9, 1e6);
  io::LogOptions options;
  options.gaps = io::GapPolicyFromString(gaps);
  options.delimiter = io::DelimiterFromString(delimiter);
  options.names = names;
  options.skip_rows = skip_rows;
  options.bad_lines = io::BadLinesFromString(bad_lines);
  options.ulog.topic = ulog_topic;
  options.ulog.units = allan::RateUnitFromString(ulog_units);
  options.ulog_instance = ulog_instance;
  tasks::TaskLog log;
  {
    py::gil_scoped_release release;  // a long log takes a while; nothing here touches Python
    log = tasks::ReadTaskLog(path, options, rate_hz.value_or(0.0));
  }
  for (const std::string& w :
       tasks::LogWarnings(log, log.rate_how, {}, tasks::Audience::kKeywords)) {
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
  }
  py::dict columns;
  // ColumnRef: the table's own values, copied once into the array.
  for (const std::string& name : log.table.header()) {
    columns[Text(name)] = ToArray(log.table.ColumnRef(name));
  }
  py::dict d;
  d["path"] = path;
  d["columns"] = columns;
  d["rate_hz"] = log.rate_hz;
  d["rate_source"] = tasks::RateSourceText(log.rate_how, /*flags=*/false);
  if (log.logged.empty()) {
    d["logged"] = py::none();
  } else {
    py::array_t<bool> logged(static_cast<py::ssize_t>(log.logged.size()));
    auto flags = logged.mutable_unchecked<1>();
    for (size_t i = 0; i < log.logged.size(); ++i)
      flags(static_cast<py::ssize_t>(i)) = log.logged[i];
    d["logged"] = logged;
  }
  d["record_starts"] = log.record_starts;
  py::list notes;  // as the CLI prints them (a gap note may hold a line per skipped row)
  for (const std::string* note : {&log.gap_note, &log.time_note}) {
    if (!note->empty()) notes.append(Text(*note));
  }
  d["notes"] = notes;
  return d;
}

py::dict ReadUlog(const std::string& path, const std::vector<std::string>& decode) {
  const io::Ulog log = io::ReadUlog(path, decode);
  py::dict d;
  d["version"] = log.version;
  d["start_us"] = log.start_us;
  py::dict info, parameters;
  for (const auto& [key, value] : log.info) info[Text(key)] = Text(value);
  for (const auto& [key, value] : log.parameters) parameters[Text(key)] = value;
  d["info"] = info;
  d["parameters"] = parameters;
  d["dropouts"] = log.dropouts;
  d["appended"] = log.appended;
  d["warnings"] = Texts(log.warnings);
  py::list series;
  for (const io::UlogSeries& s : log.series) series.append(SeriesDict(s));
  d["series"] = series;
  d["listing"] = Text(io::DescribeUlog(log));
  return d;
}

py::dict UlogColumns(const std::string& path, const std::string& topic, int instance,
                     const std::vector<std::string>& axes, const std::string& temperature_field,
                     const std::string& units) {
  const io::UlogConversion conversion{.topic = topic,
                                      .axes = axes,
                                      .temperature = temperature_field,
                                      .units = allan::RateUnitFromString(units)};
  // One series: "every instance" (a negative one to SeriesWithSamples) is not an answer here.
  if (instance < 0 || instance > io::kMaxUlogInstance) {
    ThrowOption("instance", std::to_string(instance),
                "an integer in [0, " + std::to_string(io::kMaxUlogInstance) + "]");
  }
  const io::Ulog log = io::ReadUlog(path, {topic});
  const io::UlogSeries& s = *io::SeriesWithSamples(log, path, topic, instance).front();
  py::dict d;
  for (const io::CsvColumn& c : io::UlogColumns(s, conversion)) d[py::str(c.name)] = ToArray(c.values);
  d["warnings"] = Texts(log.warnings);
  return d;
}

py::dict Plan(double hours, double min_c, double max_c, double rate, double dwell_min) {
  drift::CalibrationPlan plan;
  // A refusal names the keyword (rate, dwell_min), as the CLI's names its flag.
  ValidateAsSettings({{"rate_k_per_min", "rate"}, {"shortest_dwell_min", "dwell_min"}}, [&] {
    plan = drift::PlanCalibration({.hours = hours,
                                   .min_c = min_c,
                                   .max_c = max_c,
                                   .rate_k_per_min = rate,
                                   .shortest_dwell_min = dwell_min});
  });
  py::dict d;
  const auto n = static_cast<Eigen::Index>(plan.time_s.size());
  d["time_s"] = ToArray(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(plan.time_s.data(), n)));
  d["temperature_c"] =
      ToArray(Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(plan.temperature_c.data(), n)));
  d["rate_k_per_min"] = plan.rate_k_per_min;
  py::list steps;
  for (const drift::PlanStep& s : plan.steps) {
    py::dict step;
    step["start_s"] = s.start_s;
    step["end_s"] = s.end_s;
    step["from_c"] = s.from_c;
    step["to_c"] = s.to_c;
    step["why"] = s.why;
    steps.append(step);
  }
  d["steps"] = steps;
  d["warnings"] = plan.warnings;
  d["explanation"] = plan.Explanation();
  return d;
}

}  // namespace

void BindLogs(py::module_& m) {
  using py::arg;
  const io::LogOptions ld;
  m.def("read_log", &ReadLog, arg("path"), py::kw_only(),
        arg("gaps") = std::string(io::ToString(ld.gaps)), arg("rate_hz") = py::none(),
        arg("delimiter") = std::string(io::ToString(ld.delimiter)), arg("names") = ld.names,
        arg("skip_rows") = ld.skip_rows, arg("bad_lines") = std::string(io::ToString(ld.bad_lines)),
        arg("ulog_topic") = ld.ulog.topic, arg("ulog_instance") = ld.ulog_instance,
        arg("ulog_units") = std::string(allan::ToString(ld.ulog.units)));
  m.def("read_ulog", &ReadUlog, arg("path"), py::kw_only(),
        arg("decode") = std::vector<std::string>{"sensor_gyro"});
  const io::UlogConversion cd;
  m.def("ulog_columns", &UlogColumns, arg("path"), py::kw_only(), arg("topic") = cd.topic,
        arg("instance") = 0, arg("axes") = cd.axes, arg("temperature_field") = cd.temperature,
        arg("units") = allan::ToString(cd.units));
  const drift::PlanSettings pd;
  m.def("plan", &Plan, py::kw_only(), arg("hours") = pd.hours, arg("min_c") = pd.min_c,
        arg("max_c") = pd.max_c, arg("rate") = pd.rate_k_per_min,
        arg("dwell_min") = pd.shortest_dwell_min);
}

}  // namespace gyrodrift::python
