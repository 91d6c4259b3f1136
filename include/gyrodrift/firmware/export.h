// Firmware export: compensate-mode drift models, one per gyro axis, as a dependency-free C99
// header that a navigation computer compiles, as a plain JSON of their coefficients for other
// tools (docs/firmware.md gives the header's API and the JSON schema), or as the parameters of
// PX4's thermal compensation (RenderPx4Params: the autopilot form fitted beside each model).
//
// What the C header computes: at every sample, from the temperature channel(s) only, the drift
// estimate of each axis exactly as drift::EstimateDrift does (thermal_model.h): the cascaded
// first-order lags started in equilibrium at the first sample, the levels standardised by the
// calibration's centre and scale, their powers continued along the tangent beyond the
// calibration's range [level_min, level_max], the rate terms, the intercept, minus the estimate at
// equilibrium at reference_c when the model has one, summed over the sub-models in their order.
// The lag recursion s += g (T - s), g = 1 - exp(-dt/tau), is run on each stage's deviation below
// its input, u = input - s (u' = (u + d_input)(1 - g), the stage moving by g (u + d_input)): the
// same filter and the same first sample, but the increments of a slow lag (g = 3e-4 at tau = 1 h,
// 1 Hz) stay in the arithmetic, where s += g (T - s) in float stalls once g |T - s| is below half
// a unit of T's last place (measured: 2.6e-5 instead of 1.3e-6 of the estimate's RMS; the
// figures are in docs/firmware.md). The rest runs in the library's order, sub-model by sub-model.
// The gains are computed here, for the model's sample rate, and written as literals: the header
// needs no libm and no other header; a model is tied to its sample rate.
//
// Exportable: compensate-mode models whose sub-models are all identified thermal models
// (methods thermal, ms-elm, emd-elm), without a nonlinear correction (its sigmoid units need exp
// at every sample). Learners on thermal features (poly, elm, svr, bp) and predict-mode models are
// refused with a UsageError naming the axis and the reason.
// Cost: linear in the number of coefficients; the generated step costs per sample a few
// operations per lag stage and per regressor, no loops, no division by a variable.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/drift/thermal_model.h"
#include "gyrodrift/io/model_file.h"

namespace gyrodrift::firmware {

using io::LoadedModel;

enum class ExportFormat { kC, kCoefficientsJson, kPx4Params };
std::string_view ToString(ExportFormat format);  // "c", "json-coefficients", "px4"
ExportFormat ExportFormatFromString(std::string_view name);  // OptionError naming `format`

struct ExportOptions {
  ExportFormat format = ExportFormat::kC;
  // C: float arithmetic, constants and state instead of double (FPUs without double precision);
  // only with format kC.
  bool single_precision = false;
  // C: every identifier starts with it (`gyro_comp_step`, macros `GYRO_COMP_N_AXES`): a letter,
  // then letters, digits or underscores, at most 32 characters (C99 guarantees 63 significant
  // characters of an internal identifier; the longest suffix is 20).
  std::string prefix = "gyro_comp";
  // PX4: the DEVID of each gyro instance (PX4's sensor_gyro device_id; `gyrodrift convert --list`
  // shows it), one per three axes; only with format kPx4Params, which needs them.
  std::vector<std::uint32_t> device_ids = {};
  void Validate() const;  // throws OptionError naming the field
};

// Throws UsageError when an axis cannot run in firmware (see above; the message names the axis,
// its target column and the sub-model), when `axes` is empty, or when the axes were fitted at
// different sample rates (one step function serves them all); DataError when a model's file names
// another number of temperature channels than its thermal models take.
void RequireExportable(const std::vector<LoadedModel>& axes);

// The C99 header (see above) for `axes` (axis i = axes[i]; its name is info.target_column). The
// temperature channels are the union of the axes' columns by name, in order of appearance.
// Deterministic: the same models and options give the same bytes. Throws as RequireExportable and
// Validate, and UsageError for a constant beyond float's range with single_precision.
std::string RenderFirmwareC(const std::vector<LoadedModel>& axes, const ExportOptions& options);

// The coefficients as plain JSON (format "gyrodrift-coefficients", version 4; schema in
// docs/firmware.md), with every double written as the shortest text that reads back to it.
std::string RenderCoefficientsJson(const std::vector<LoadedModel>& axes,
                                   const ExportOptions& options);

// The polynomial an autopilot runs for one axis (drift::AutopilotForm, in the model's unit): its
// thermal sub-models' forms summed (the sum's share_kept NaN), relative to equilibrium at the
// model's reference temperature when it has one, as the full model's estimate. UsageError naming
// `label` for a model without one (not an identified compensate-mode model, or a file older than
// format 8).
drift::AutopilotForm AxisAutopilotForm(const LoadedModel& axis, const std::string& label);

// The PX4 parameter file (QGroundControl's tab-separated form: vehicle 1, component 1, name,
// value, MAV_PARAM_TYPE): TC_G_ENABLE = 1 and, for gyro instance i (axes 3i, 3i+1, 3i+2 are its
// x, y and z), TC_G{i}_ID = device_ids[i], TC_G{i}_TMIN, TMAX (the calibrated range), TREF (its
// middle) and TC_G{i}_X{k}_{axis}, the coefficients of dT^k in rad/s (AxisAutopilotForm times
// the unit's factor), floats written to 9 significant digits (they read back to the same float).
// UsageError unless there are 1 to 3 instances of 3 axes each, each instance's axes calibrated
// over one range, and every model records its unit.
std::string RenderPx4Params(const std::vector<LoadedModel>& axes,
                            const std::vector<std::uint32_t>& device_ids);

// One axis' form as the PX4 file holds it, for a front end's report: its parameters' names
// ("TC_G0 axis 0 (x_dph)") and the form in the model's unit (AxisAutopilotForm).
struct Px4AxisForm {
  std::string label;
  drift::AutopilotForm form;
};
// RenderPx4Params's text and the forms it wrote, each computed once.
struct Px4Params {
  std::string text;
  std::vector<Px4AxisForm> forms;
};
Px4Params MakePx4Params(const std::vector<LoadedModel>& axes,
                        const std::vector<std::uint32_t>& device_ids);

// What an export holds, for the CLI's report.
struct ExportSummary {
  int axes = 0;
  int channels = 0;    // temperature inputs per sample
  int states = 0;      // thermal states over every axis and sub-model
  int lag_stages = 0;  // first-order lags the step runs (states of one channel and tau share them)
  double rate_hz = 0.0;
  std::string Line() const;  // one line
};
ExportSummary SummariseExport(const std::vector<LoadedModel>& axes);

// The file of options.format: RenderFirmwareC, RenderCoefficientsJson or RenderPx4Params.
std::string RenderExport(const std::vector<LoadedModel>& axes, const ExportOptions& options);

// The `export` operation as every front end runs it: the axes of every model file, in order
// (for PX4, one file per gyro), and RenderExport's text of them. Throws as io::ReadModelFileAxes
// and RenderExport.
struct ExportResult {
  std::vector<LoadedModel> axes;
  std::string text;
  std::vector<Px4AxisForm> px4_forms;  // format px4: each axis' form, in file order
};
ExportResult ExportModelFiles(const std::vector<std::string>& model_paths,
                              const ExportOptions& options);
// The same of axes already loaded (Python's DriftModel objects), in order.
ExportResult ExportAxes(std::vector<LoadedModel> axes, const ExportOptions& options);

}  // namespace gyrodrift::firmware
