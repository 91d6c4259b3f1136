// What the model file's reader and writer share (model_file.cc, model_file_thermal.cc): numbers
// as JSON (non-finite ones as text), the reader's Node that names the file and the field in every
// refusal, and the parts written and read in a file of their own. Private to src/io.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/learner.h"
#include "gyrodrift/drift/thermal_model.h"

namespace gyrodrift::io::internal {

using nlohmann::json;

// A double as JSON: itself when finite, else "nan", "inf" or "-inf".
json Number(double v);
json Numbers(const std::vector<double>& values);
// {"rows", "cols", "data"}: the entries in column-major order.
json Array(const Eigen::MatrixXd& m);

// Reading: every access names the file and the dotted path of the field.

class Node {
 public:
  Node(const json& j, std::string path, const std::string& source)
      : j_(j), path_(std::move(path)), source_(source) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw DataError(source_ + ": field '" + path_ + "' " + what);
  }

  Node operator[](const std::string& key) const {
    if (!j_.is_object()) Fail("must be an object (found " + std::string(j_.type_name()) + ")");
    const auto it = j_.find(key);
    const std::string path = path_.empty() ? key : path_ + "." + key;
    if (it == j_.end()) throw DataError(source_ + ": field '" + path + "' is missing");
    return Node(*it, path, source_);
  }

  bool IsNull() const { return j_.is_null(); }
  const json& raw() const { return j_; }

  // Files of format 5 and older hold thread counts beside the options, the fit's execution rather
  // than the model: "threads" is read (a non-negative integer) and dropped if present.
  // ParseModelFileAxes refuses the field in newer files.
  void DropLegacyThreads() const {
    if (j_.is_object() && j_.contains("threads")) {
      (*this)["threads"].Int(0, std::numeric_limits<int>::max());
    }
  }

  double Double() const {
    if (j_.is_number()) return j_.get<double>();
    if (j_.is_string()) {
      const std::string& s = j_.get_ref<const std::string&>();
      if (s == "nan") return std::numeric_limits<double>::quiet_NaN();
      if (s == "inf") return std::numeric_limits<double>::infinity();
      if (s == "-inf") return -std::numeric_limits<double>::infinity();
    }
    Fail("must be a number (found " + Found() + ")");
  }

  long long Int(long long lo, long long hi) const {
    if (!j_.is_number_integer()) Fail("must be an integer (found " + Found() + ")");
    if (j_.is_number_unsigned() && j_.get<std::uint64_t>() > static_cast<std::uint64_t>(hi)) {
      Fail("= " + j_.dump() + ": must be in [" + std::to_string(lo) + ", " + std::to_string(hi) +
           "]");
    }
    const long long v = j_.get<long long>();
    if (v < lo || v > hi) {
      Fail("= " + std::to_string(v) + ": must be in [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
    }
    return v;
  }
  int Int() const {
    return static_cast<int>(Int(std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
  }

  std::uint64_t U64() const {
    if (!j_.is_number_unsigned()) Fail("must be an unsigned integer (found " + Found() + ")");
    return j_.get<std::uint64_t>();
  }

  bool Bool() const {
    if (!j_.is_boolean()) Fail("must be true or false (found " + Found() + ")");
    return j_.get<bool>();
  }

  std::string String() const {
    if (!j_.is_string()) Fail("must be a string (found " + Found() + ")");
    return j_.get<std::string>();
  }

  std::vector<Node> Items() const {
    if (!j_.is_array()) Fail("must be an array (found " + Found() + ")");
    std::vector<Node> items;
    for (size_t i = 0; i < j_.size(); ++i) {
      items.emplace_back(j_[i], path_ + "[" + std::to_string(i) + "]", source_);
    }
    return items;
  }

  std::vector<int> Ints() const {
    std::vector<int> out;
    for (const Node& n : Items()) out.push_back(n.Int());
    return out;
  }
  std::vector<double> Doubles() const {
    std::vector<double> out;
    for (const Node& n : Items()) out.push_back(n.Double());
    return out;
  }

  // An enum through its FromString, whose UsageError becomes a DataError naming the field.
  template <class F>
  auto Enum(F from_string) const -> decltype(from_string(std::string_view())) {
    const std::string text = String();
    try {
      return from_string(text);
    } catch (const UsageError& e) {
      Fail("= '" + text + "' is not understood (" + e.what() + ")");
    }
  }

  Eigen::MatrixXd Matrix() const {
    const long long max_size = 1LL << 31;
    const long long rows = (*this)["rows"].Int(0, max_size);
    const long long cols = (*this)["cols"].Int(0, max_size);
    const std::vector<Node> data = (*this)["data"].Items();
    if (static_cast<long long>(data.size()) != rows * cols) {
      Fail("has " + std::to_string(data.size()) + " values for a " + std::to_string(rows) + " x " +
           std::to_string(cols) + " array (rows * cols expected)");
    }
    Eigen::MatrixXd m(rows, cols);
    for (size_t i = 0; i < data.size(); ++i) m.data()[i] = data[i].Double();
    return m;
  }

 private:
  std::string Found() const {
    if (j_.is_string()) return "\"" + j_.get<std::string>() + "\"";
    if (j_.is_number() || j_.is_boolean() || j_.is_null()) return j_.dump();
    return j_.type_name();
  }

  const json& j_;
  std::string path_;
  const std::string& source_;
};

json LearnerJson(const drift::Learner& learner);
std::shared_ptr<const drift::Learner> ReadLearner(const Node& n, const std::string& sub_name);

// The drift options (model_file_options.cc).
drift::DriftOptions ReadOptions(const Node& n);

// The thermal models and their identification options (model_file_thermal.cc).
json ThermalOptionsJson(const drift::ThermalModelOptions& t);
json ThermalJson(const drift::ThermalRegression& t);
drift::ThermalModelOptions ReadThermalOptions(const Node& n);
std::shared_ptr<const drift::ThermalRegression> ReadThermal(const Node& n);

}  // namespace gyrodrift::io::internal
