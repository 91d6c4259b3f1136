// A terminal progress bar for long subcommands, on stderr:
//   [##########----------]  48%  causal MS-ELM  elapsed 1m12s  left 1m18s
// Shown only when stderr is a terminal and the command is not --quiet, so logs and pipes stay
// clean. Work is described as weighted stages (the weights are the expected cost of each, e.g.
// measured seconds); a stage reports its own fraction and the bar maps it onto the whole. The
// remaining time is elapsed * (1 - f) / f, counted down between reports; a ticker thread redraws
// twice a second so the clock moves during a long step that reports nothing.
// Thread-safe: Update may be called from any thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace gyrodrift::cli {

class ProgressBar {
 public:
  // stage_weights: relative cost of each stage, each >= 0, sum > 0 (else all stages count equal).
  // enabled: false (--quiet) or stderr not a terminal -> draws nothing.
  ProgressBar(std::vector<double> stage_weights, bool enabled);
  ~ProgressBar();  // Finish()
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // Starts stage `index` (0-based) with a label; earlier stages count as done.
  void BeginStage(int index, const std::string& label);
  // Fraction of the current stage done, in [0, 1]; the label replaces the stage's label if not
  // empty.
  void Update(double stage_fraction, const std::string& label = {});
  // Prints text to stdout (the bar is cleared first and redrawn after, so they do not mix).
  void Print(const std::string& text);
  // Clears the line (if anything was drawn) and stops the ticker. Idempotent.
  void Finish();
  bool shown() const { return enabled_; }
  double elapsed_s() const;

  // Text of the bar for a fraction, elapsed and remaining time (remaining < 0: unknown), at
  // most max_columns characters (0 = no limit): a long label is shortened with "..." so the
  // line never wraps, which would leave a trail of half-erased lines.
  static std::string Format(double fraction, const std::string& label, double elapsed_s,
                            double remaining_s, int width, int max_columns = 0);
  // "45s", "3m05s", "1h02m".
  static std::string FormatSeconds(double seconds);

 private:
  void DrawLocked();
  std::vector<double> start_;  // cumulative share where each stage starts
  std::vector<double> share_;  // share of each stage
  bool enabled_;
  int stage_ = 0;
  double fraction_ = 0.0;  // overall
  std::string label_;
  std::chrono::steady_clock::time_point begin_, last_report_;
  double remaining_at_report_ = -1.0;
  size_t drawn_width_ = 0;
  bool finished_ = false;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::thread ticker_;
};

}  // namespace gyrodrift::cli
