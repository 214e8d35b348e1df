// Terminal progress line; see progress.hpp.
#include "progress.hpp"

#include <fmt/format.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape::app {
namespace {

constexpr double kRedrawSeconds = 0.1;  // at most 10 updates a second

std::string clock_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const auto s = static_cast<long>(std::lround(seconds));
  return s >= 3600 ? fmt::format("{}:{:02}:{:02}", s / 3600, (s / 60) % 60, s % 60) : fmt::format("{}:{:02}", s / 60, s % 60);
}

int terminal_columns(std::FILE* out) {
  winsize size{};
  if (ioctl(fileno(out), TIOCGWINSZ, &size) == 0 && size.ws_col >= 20) return size.ws_col;
  return 80;
}

}  // namespace

Progress::Progress(std::string task, double total)
    : Progress(std::move(task), total, stderr, isatty(fileno(stderr)) != 0) {}

Progress::Progress(std::string task, double total, std::FILE* out, bool is_terminal, double quiet_seconds)
    : task_(std::move(task)),
      total_(total > 0 ? total : 0),
      out_(out),
      enabled_(is_terminal && out != nullptr),
      quiet_seconds_(quiet_seconds) {}

Progress::~Progress() { finish(); }

void Progress::update(double done, std::string_view detail) {
  if (!enabled_) return;
  const Clock::time_point now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < quiet_seconds_ || std::chrono::duration<double>(now - last_draw_).count() < kRedrawSeconds) return;
  last_draw_ = now;
  draw(done, detail, elapsed);
}

void Progress::draw(double done, std::string_view detail, double elapsed_s) {
  std::string line = task_;
  if (total_ > 0) {
    const double fraction = std::clamp(done / total_, 0.0, 1.0);
    constexpr int kBar = 24;
    const int filled = static_cast<int>(fraction * kBar);
    const double left = fraction > 0 ? elapsed_s * (1 - fraction) / fraction : std::numeric_limits<double>::quiet_NaN();
    line += fmt::format(" [{}{}] {:3.0f}% {:.0f}/{:.0f} {} elapsed, {} left", std::string(static_cast<size_t>(filled), '#'),
                        std::string(static_cast<size_t>(kBar - filled), ' '), 100 * fraction, done, total_,
                        clock_text(elapsed_s), clock_text(left));
  } else {
    line += fmt::format(" {:.0f} done, {} elapsed", done, clock_text(elapsed_s));
  }
  if (!detail.empty()) line += fmt::format(" ({})", detail);
  // Fit the terminal so the line never wraps (a wrapped line cannot be redrawn with \r).
  const auto columns = static_cast<size_t>(terminal_columns(out_) - 1);
  if (line.size() > columns) line.resize(columns);
  // stdio, not fmt::print: a terminal that went away must not throw (finish() runs in a destructor).
  std::fputc('\r', out_);
  std::fputs(line.c_str(), out_);
  std::fputs("\x1b[K", out_);
  std::fflush(out_);
  shown_ = true;
}

void Progress::finish() {
  if (!shown_) return;
  std::fputs("\r\x1b[K", out_);
  std::fflush(out_);
  shown_ = false;
}

}  // namespace drape::app
