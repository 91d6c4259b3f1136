// Bindings of the logs people have and the runs they plan: read_ulog, ulog_columns (what
// `gyrodrift convert` writes) and plan (what `gyrodrift plan` writes), as the CLI computes them.
#include "bindings.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/drift/calibration_plan.h"
#include "gyrodrift/io/ulog.h"

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
  if (instance < 0) ThrowOption("instance", std::to_string(instance), "an integer >= 0");
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
