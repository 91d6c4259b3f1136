// The compensate-mode models reduced to what a firmware step computes (every renderer of
// export.h reads them): the lag chains shared between states, each axis's sub-models with their
// static powers, states and hysteresis. Private to src/firmware.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/firmware/export.h"

namespace gyrodrift::firmware::internal {

using io::LoadedModel;

// A chain of first-order lags of one channel with one time constant; every state of that channel
// and constant reads its stages (they are the same recursion), up to the deepest order asked.
struct Chain {
  int channel = 0;  // global channel index
  double tau_s = 0.0;
  double dt_s = 0.0;  // the sample period of the model it serves
  double gain = 0.0;  // 1 - exp(-dt/tau)
  int stages = 0;
  int first = 0;  // index of its first stage in the state's lag array
};

struct State {
  int chain = 0;
  int order = 0;
  double centre_c = 0.0, scale_k = 0.0;
  double level_min = 0.0, level_max = 0.0;
  std::vector<double> powers;  // coefficients of the level's powers 1..max_power
  double rate = 0.0;           // coefficient of the level's rate, per K/s
  // The rate's range; beyond an edge it moves at rate_beyond times its slope (0: held).
  double rate_min = -std::numeric_limits<double>::infinity();
  double rate_max = std::numeric_limits<double>::infinity();
  double rate_beyond = 0.0;
};

// Static powers of one channel's standardised level, continued along their tangent beyond
// [level_min, level_max].
struct Static {
  int channel = 0;  // global channel index
  double centre_c = 0.0, scale_k = 0.0;
  double level_min = 0.0, level_max = 0.0;
  std::vector<double> powers;  // coefficients of the powers 1..
};

// The hysteresis term of a sub-model: the play operator of one of its states' level.
struct Hysteresis {
  int state = -1;  // index in Sub::states; -1: none
  int slot = 0;    // index of its play in the step's state arrays
  double width_k = 0.0;
  double coefficient = 0.0;
};

struct Sub {
  std::string name;
  bool zero = false;  // a sub-model without a model (old files' noise group): contributes 0
  double intercept = 0.0;
  double reference_estimate = 0.0;  // subtracted when the model has a reference temperature
  std::vector<Static> statics;
  std::vector<State> states;
  Hysteresis hysteresis;
};

struct Axis {
  std::string name;  // target column
  std::string summary;
  std::string source;  // training file
  std::string method;
  double reference_c = std::numeric_limits<double>::quiet_NaN();
  std::vector<Sub> subs;
};

struct Plan {
  double rate_hz = 0.0;  // of the first axis (the header's RATE_HZ); each chain keeps its own gain
  std::vector<std::string> channels;
  std::vector<Chain> chains;
  std::vector<Axis> axes;
  int lag_stages = 0;
  int states = 0;
  int plays = 0;  // hysteresis terms
};

// "a,b" -> {"a", "b"}: a model file's temperature column names.
std::vector<std::string> SplitNames(const std::string& names);
// "axis 0 (rate_dph)", naming an axis in messages.
std::string AxisLabel(size_t i, const LoadedModel& m);
// UsageError when two of `axes` have one target column and a temperature column in common: two
// gyros logged alike (convert --instance all), whose temperature channels the export joins by
// name, so that both would read the first gyro's sensor. (Axes of one gyro share its sensor under
// their own target names; nothing tells two gyros apart then.)
void RequireDistinctAxes(const std::vector<LoadedModel>& axes);

// The plan of `axes` (RequireExportable first).
Plan MakePlan(const std::vector<LoadedModel>& axes);

}  // namespace gyrodrift::firmware::internal
