#include "progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>

namespace gyrodrift::cli {

ProgressBar::ProgressBar(std::vector<double> stage_weights, bool enabled)
    : enabled_(enabled && ::isatty(STDERR_FILENO) != 0) {
  if (stage_weights.empty()) stage_weights.push_back(1.0);
  double total = 0.0;
  for (double& w : stage_weights) {
    if (!(w >= 0.0) || !std::isfinite(w)) w = 0.0;
    total += w;
  }
  if (total <= 0.0) {
    std::fill(stage_weights.begin(), stage_weights.end(), 1.0);
    total = static_cast<double>(stage_weights.size());
  }
  double at = 0.0;
  for (double w : stage_weights) {
    start_.push_back(at / total);
    share_.push_back(w / total);
    at += w;
  }
  begin_ = last_report_ = std::chrono::steady_clock::now();
  if (enabled_) {
    ticker_ = std::thread([this] {
      std::unique_lock<std::mutex> lock(mutex_);
      while (!finished_) {
        wake_.wait_for(lock, std::chrono::milliseconds(500));
        if (!finished_) DrawLocked();
      }
    });
  }
}

ProgressBar::~ProgressBar() { Finish(); }

double ProgressBar::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - begin_).count();
}

void ProgressBar::BeginStage(int index, const std::string& label) {
  std::lock_guard<std::mutex> lock(mutex_);
  stage_ = std::clamp(index, 0, static_cast<int>(start_.size()) - 1);
  label_ = label;
  fraction_ = std::max(fraction_, start_[static_cast<size_t>(stage_)]);
  last_report_ = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(last_report_ - begin_).count();
  remaining_at_report_ = fraction_ > 0.01 ? elapsed * (1.0 - fraction_) / fraction_ : -1.0;
  if (enabled_) DrawLocked();
}

void ProgressBar::Update(double stage_fraction, const std::string& label) {
  std::lock_guard<std::mutex> lock(mutex_);
  const size_t s = static_cast<size_t>(stage_);
  const double f = start_[s] + share_[s] * std::clamp(stage_fraction, 0.0, 1.0);
  fraction_ = std::max(fraction_, f);
  if (!label.empty()) label_ = label;
  last_report_ = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(last_report_ - begin_).count();
  remaining_at_report_ = fraction_ > 0.01 ? elapsed * (1.0 - fraction_) / fraction_ : -1.0;
  if (enabled_) DrawLocked();
}

void ProgressBar::DrawLocked() {
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - begin_).count();
  double remaining = -1.0;
  if (remaining_at_report_ >= 0.0) {
    remaining = std::max(
        0.0, remaining_at_report_ - std::chrono::duration<double>(now - last_report_).count());
  }
  winsize size{};
  const int columns =
      ::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0 ? size.ws_col : 80;
  // One column short of the width: a line that fills the last column wraps on some terminals.
  std::string line = Format(fraction_, label_, elapsed, remaining, 24, columns - 1);
  const size_t width = line.size();
  if (width < drawn_width_) line.append(drawn_width_ - width, ' ');
  drawn_width_ = width;
  std::fprintf(stderr, "\r%s", line.c_str());
  std::fflush(stderr);
}

void ProgressBar::Print(const std::string& text) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (enabled_ && drawn_width_ > 0 && !finished_) {
    std::fprintf(stderr, "\r%s\r", std::string(drawn_width_, ' ').c_str());
    std::fflush(stderr);
    drawn_width_ = 0;
  }
  std::fputs(text.c_str(), stdout);
  std::fflush(stdout);
  if (enabled_ && !finished_) DrawLocked();
}

void ProgressBar::Finish() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    finished_ = true;
    if (enabled_ && drawn_width_ > 0) {
      std::fprintf(stderr, "\r%s\r", std::string(drawn_width_, ' ').c_str());
      std::fflush(stderr);
    }
  }
  wake_.notify_all();
  if (ticker_.joinable()) ticker_.join();
}

std::string ProgressBar::FormatSeconds(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  const long s = std::lround(seconds);
  char buffer[32];
  if (s < 60) {
    std::snprintf(buffer, sizeof(buffer), "%lds", s);
  } else if (s < 3600) {
    std::snprintf(buffer, sizeof(buffer), "%ldm%02lds", s / 60, s % 60);
  } else {
    std::snprintf(buffer, sizeof(buffer), "%ldh%02ldm", s / 3600, (s % 3600) / 60);
  }
  return buffer;
}

std::string ProgressBar::Format(double fraction, const std::string& label, double elapsed_s,
                                double remaining_s, int width, int max_columns) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  const int filled = static_cast<int>(std::floor(fraction * width));
  std::string bar = "[" + std::string(static_cast<size_t>(filled), '#') +
                    std::string(static_cast<size_t>(width - filled), '-') + "]";
  char percent[16];
  std::snprintf(percent, sizeof(percent), "%4d%%", static_cast<int>(std::floor(fraction * 100.0)));
  const std::string times = "  elapsed " + FormatSeconds(elapsed_s) + "  left " +
                            (remaining_s < 0.0 ? std::string("?") : FormatSeconds(remaining_s));
  std::string shown = label;
  if (max_columns > 0) {
    const long room = static_cast<long>(max_columns) -
                      static_cast<long>(bar.size() + std::strlen(percent) + 2 + times.size());
    if (static_cast<long>(shown.size()) > room) {
      shown = room >= 4 ? shown.substr(0, static_cast<size_t>(room - 3)) + "..." : "";
    }
  }
  std::string text = bar + percent + "  " + shown + times;
  if (max_columns > 0 && static_cast<long>(text.size()) > max_columns) {
    text.resize(static_cast<size_t>(std::max(max_columns, 1)));
  }
  return text;
}

}  // namespace gyrodrift::cli
