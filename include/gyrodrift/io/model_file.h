// Model files: a fitted drift::DriftModel saved as JSON and read back with predictions identical
// to the bit.
//
// Layout (format "gyrodrift-model"; every field required on reading):
//   format, format_version, tool_version
//   then one axis's fields at the top level, or, for a file of several gyro axes (fit --target
//   gyro_x,gyro_y,gyro_z), an array "axes" of 2 to kMaxModelAxes objects each holding them:
//   training   target_column, temperature_column ("" if none), rate_unit (format 4), samples,
//              source (informative)
//   options    every field of drift::DriftOptions (mode, method, decomposition with its sifting
//              rule, selection with its KDE and Monte-Carlo settings, features with the thermal
//              time constants and rate_hz, learner, lag candidates, seed); enums as the
//              strings their ToString() gives
//   model      lags, training_imfs, training_samples, the training reports, lag validation RMSE,
//              and sub_models: name, imfs, has_residue, learner (null for the zero sub-model of
//              the noise group in compensate mode) = {kind, arrays, scalars, texts}, each array
//              {rows, cols, data} with data column-major
//   checksum   "fnv1a64:<16 hex digits>" of the compact dump of everything else
// Doubles: nlohmann/json prints the shortest decimal that reads back to the same double and parses
// with correct rounding, so finite values survive exactly; NaN and +-infinity, which JSON lacks,
// are written as the strings "nan", "inf", "-inf". Seeds are unsigned 64-bit integers.
// The checksum is FNV-1a 64 (Fowler, Noll & Vo), over the compact, key-sorted dump, so a damaged
// or hand-edited number is caught before anything is used; it guards against accidents, not
// against forgery.
// Errors: an unreadable or unwritable file -> IoError; anything wrong inside (not JSON, another
// format or version, checksum mismatch, a missing field, a wrong type or shape, options out of
// range, learner parameters that do not rebuild) -> DataError naming the file and the field.
// Cost: linear in the number of stored parameters.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/drift_model.h"

namespace gyrodrift::io {

inline constexpr std::string_view kModelFormat = "gyrodrift-model";
// Version 2 stores the thermal feature set, whether the time constants were limited, and the
// training temperature range; version-1 files (all fitted with the "auto" set) still load. A
// version-1 reader refuses version 2, which it would otherwise misread.
// Version 3 adds identified thermal sub-models ("thermal" beside "learner") and the options of
// their identification; older files read with the defaults.
// Version 4 adds files of several axes ("axes"; a one-axis file keeps the version-3 layout) and
// the target's rate unit (training.rate_unit).
// Version 5 adds the thermal models' hysteresis term and the options that choose it (older files
// read as identified without it).
// Version 6 drops the thread counts (options.threads, options.decomposition.threads,
// options.selection.threads and its monte_carlo.threads, options.learner.threads, and the
// "threads" scalar of ELM and SVR learners): they are how a fit ran (common/execution.h), never
// part of the model, whose every bit is the same for any count. Older files still load, the
// counts read and dropped; a version-6 file that holds one is refused as an unknown field.
// Version 7 (issues 22, 23): a thermal model's static powers of T per channel with their range
// (static_power, static_range; older files' "linear" reads as power 1, unbounded), each state's
// rate range (held at its edges; older files' rates run unheld), the structure rules' options
// (max_condition, standard_errors) and the report's structure, held-out errors and advice; a
// predict-mode sub-model predicted by its training mean (MS-ELM's noise group,
// drift_model.h SubModel::mean) holds "mean" and a null "learner"; the baselines
// (drift/baseline.h: methods none, constant, persistence, trailing-mean, exp-smoothing,
// kalman-level, kalman-trend) hold a "baseline" (its parameters) in their one sub-model and no
// learner. Older files have none of these.
// Version 8 (issue 26): a thermal model's autopilot form ("autopilot": degree, tref_c, tmin_c,
// tmax_c, coefficients of dT^0..3, share_kept); older files read without one (not fitted).
// Version 9 (issue 22): each state's "rate_beyond", the share of its rate's slope kept beyond its
// rate range (older files: 0, held at the edges).
inline constexpr int kModelFormatVersion = 9;
inline constexpr int kMaxModelAxes = 64;
inline constexpr int kOldestReadableModelFormatVersion = 1;

// What the model was trained on, beside the model itself.
struct ModelFileInfo {
  std::string target_column = {};  // CSV column of the gyro output the model was fitted on
  // CSV column(s) of the temperature, comma-separated in channel order; "" when the model has none
  std::string temperature_column = {};
  std::string source = {};        // training file, informative only
  std::string tool_version = {};  // ignored on writing (the running version is written)
  // Unit of the target column and of every estimate: "dph", "dps" or "rads" (allan::RateUnit
  // names); "" in files written before format 4, which did not record it.
  std::string rate_unit = "dph";
};

// One axis of a model file: a gyro output column's model.
struct LoadedModel {
  drift::DriftModel model;
  ModelFileInfo info;
};

// Renders / writes a model file of one or several axes (distinct target columns, in order).
// Throws UsageError when the model cannot be stored (a predict-mode sub-model without a learner,
// no axis, repeated targets), IoError when the file cannot be written (atomically: nothing partial
// is left).
std::string RenderModelFile(const std::vector<LoadedModel>& axes);
std::string RenderModelFile(const drift::DriftModel& model, const ModelFileInfo& info);
void WriteModelFile(const std::string& path, const std::vector<LoadedModel>& axes);
void WriteModelFile(const std::string& path, const drift::DriftModel& model,
                    const ModelFileInfo& info);

// Parses / reads every axis of a model file; `source` names it in messages. Throws DataError /
// IoError.
std::vector<LoadedModel> ParseModelFileAxes(const std::string& text, const std::string& source);
std::vector<LoadedModel> ReadModelFileAxes(const std::string& path);
// The same for commands that take one axis: a file of several throws UsageError naming them.
LoadedModel ParseModelFile(const std::string& text, const std::string& source);
LoadedModel ReadModelFile(const std::string& path);

// Every option of a DriftOptions as JSON (the "options" object of a model file); used by the CLI
// sidecars too. DriftOptionsFromJson reads it back (DataError naming a missing or bad field).
nlohmann::json DriftOptionsToJson(const drift::DriftOptions& options);
drift::DriftOptions DriftOptionsFromJson(const nlohmann::json& json, const std::string& source);

// FNV-1a 64 of the bytes of text (common/random.h), as the checksum uses it.
using gyrodrift::Fnv1a64;

}  // namespace gyrodrift::io
