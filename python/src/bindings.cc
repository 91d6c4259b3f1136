// The shared helpers of the bindings (bindings.h).
#include "bindings.h"

#include "gyrodrift/drift/temperature_check.h"
#include "gyrodrift/tasks/settings_json.h"

namespace gyrodrift::python {

// A 1-D float64 copy of any array-like (lists, float32, strided views), checked under the GIL so
// the computation can run without it.
Eigen::VectorXd ToVector(const Array& a, const char* name) {
  if (a.ndim() != 1) {
    throw UsageError(std::string(name) + ": must be a 1-D array (got " + std::to_string(a.ndim()) +
                     " dimensions)");
  }
  Eigen::VectorXd v(a.shape(0));
  std::copy(a.data(), a.data() + a.shape(0), v.data());
  return v;
}

// N x C from a 1-D array (one column) or an (N, C) array.
Eigen::MatrixXd ToMatrix(const Array& a, const char* name) {
  if (a.ndim() == 1) return ToVector(a, name);
  if (a.ndim() != 2) {
    throw UsageError(std::string(name) + ": must be a 1-D or 2-D array (got " +
                     std::to_string(a.ndim()) + " dimensions)");
  }
  Eigen::MatrixXd m(a.shape(0), a.shape(1));
  auto r = a.unchecked<2>();
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    for (py::ssize_t j = 0; j < a.shape(1); ++j) m(i, j) = r(i, j);
  return m;
}

py::array_t<double> ToArray(const Eigen::VectorXd& v) {
  py::array_t<double> a(v.size());
  std::copy(v.data(), v.data() + v.size(), a.mutable_data());
  return a;
}

// N x K as an (N, K) array in Eigen's column-major order (one memcpy; each IMF imfs[:, k] is
// then contiguous).
py::array_t<double, py::array::f_style> ToArray(const Eigen::MatrixXd& m) {
  py::array_t<double, py::array::f_style> a({m.rows(), m.cols()});
  std::copy(m.data(), m.data() + m.size(), a.mutable_data());
  return a;
}

// ---- long calls: progress and Ctrl-C ---------------------------------------------------------

// Ctrl-C during a long call: bindings.h.
std::atomic<unsigned> g_interrupts{0};
std::mutex g_sigint_mutex;
int g_running_calls = 0;             // guarded by g_sigint_mutex
bool g_handler_installed = false;    // guarded by g_sigint_mutex
struct sigaction g_replaced_sigint;  // written before ours is installed, read by it

extern "C" void InterruptHandler(int signal, siginfo_t* info, void* context) {
  g_interrupts.fetch_add(1, std::memory_order_relaxed);
  if (g_replaced_sigint.sa_flags & SA_SIGINFO) {
    g_replaced_sigint.sa_sigaction(signal, info, context);
  } else {
    g_replaced_sigint.sa_handler(signal);
  }
}

// A record of the task layer as Python objects: the dict the sidecar's JSON object would load as,
// but with NaN kept as NaN (the JSON file writes null).
py::object ToPython(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [key, value] : j.items()) d[py::str(key)] = ToPython(value);
      return d;
    }
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& value : j) l.append(ToPython(value));
      return l;
    }
    case nlohmann::json::value_t::string:
      return py::str(j.get<std::string>());
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(j.get<double>());
    default:
      return py::none();
  }
}

namespace {

// A keyword's value as JSON for the settings' reader: None, bools, integers (numpy's too),
// numbers, strings and sequences of them; anything else is refused naming the keyword.
nlohmann::json KeywordJson(const std::string& key, const py::handle& value) {
  const auto refuse = [&]() -> nlohmann::json {
    throw OptionError(key, py::repr(value).cast<std::string>(),
                      "a number, a string, true/false or a sequence of them");
  };
  if (value.is_none()) return nullptr;
  if (PyBool_Check(value.ptr())) return value.cast<bool>();
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  // Looked up once and kept (released: never decref'd at interpreter exit).
  static const py::handle numpy_bool =
      py::object(py::module_::import("numpy").attr("bool_")).release();
  if (py::isinstance(value, numpy_bool)) return value.cast<bool>();
  // Sequences before numbers: a numpy array also has __index__ and __float__ (of one element).
  if (!PyFloat_Check(value.ptr()) && !py::isinstance<py::dict>(value) &&
      py::isinstance<py::iterable>(value)) {
    nlohmann::json out = nlohmann::json::array();
    for (const py::handle item : value) {
      if (item.is_none()) return refuse();
      out.push_back(KeywordJson(key, item));
    }
    return out;
  }
  if (PyIndex_Check(value.ptr())) {
    const py::object i = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
    if (!i) throw py::error_already_set();
    int overflow = 0;
    const long long v = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
    if (overflow == 0) {
      // Non-negative as unsigned: the reader takes a seed as a non-negative integer.
      return v >= 0 ? nlohmann::json(static_cast<std::uint64_t>(v)) : nlohmann::json(v);
    }
    const unsigned long long u = PyLong_AsUnsignedLongLong(i.ptr());
    if (PyErr_Occurred()) {
      PyErr_Clear();
      return refuse();
    }
    return static_cast<std::uint64_t>(u);
  }
  if (PyFloat_Check(value.ptr()) || py::hasattr(value, "__float__")) {
    const double v = PyFloat_AsDouble(value.ptr());
    if (PyErr_Occurred()) throw py::error_already_set();
    return v;
  }
  return refuse();
}

// The settings no call takes as a keyword (FitKeywordDefaults).
const std::vector<std::string> kNotKeywords = {"mode", "has_temperature"};

}  // namespace

nlohmann::json FitKeywordDefaults() {
  nlohmann::json j = tasks::FitSettingsToJson(drift::FitSettings{});
  for (const std::string& key : kNotKeywords) j.erase(key);
  return j;
}

drift::FitSettings FitSettingsOf(const py::kwargs& keywords, drift::FitSettings base,
                                 const char* function, const std::vector<std::string>& own) {
  static const nlohmann::json known = FitKeywordDefaults();
  nlohmann::json given = nlohmann::json::object();
  for (const auto& [name, value] : keywords) {
    const std::string key = py::str(name).cast<std::string>();
    if (!known.contains(key) || std::find(own.begin(), own.end(), key) != own.end()) {
      std::string names;
      for (const auto& [k, v] : known.items()) {
        if (std::find(own.begin(), own.end(), k) != own.end()) continue;
        names += (names.empty() ? "" : ", ") + k;
      }
      throw py::type_error(std::string(function) + "() got an unexpected keyword argument '" + key +
                           "' (its settings: " + names + ")");
    }
    if (!value.is_none()) given[key] = KeywordJson(key, value);
  }
  tasks::FitSettingsFromJson(given, &base);
  return base;
}

void WarnOfTemperatures(const Eigen::MatrixXd& temperature, const std::vector<std::string>& names) {
  for (Eigen::Index c = 0; c < temperature.cols(); ++c) {
    const std::string w =
        drift::TemperatureWarning(temperature.col(c), names.at(static_cast<size_t>(c)));
    if (!w.empty() && PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) {
      throw py::error_already_set();
    }
  }
}

std::vector<std::string> TemperatureNames(Eigen::Index columns) {
  if (columns == 1) return {"temperature_c"};
  std::vector<std::string> names;
  for (Eigen::Index c = 0; c < columns; ++c)
    names.push_back("temperature_c" + std::to_string(c + 1));
  return names;
}

}  // namespace gyrodrift::python
