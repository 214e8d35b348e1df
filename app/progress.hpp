#pragma once
// A terminal progress line for long runs (simulation iterations, benchmarks, batch renders).
//
//   drape::app::Progress progress("draping", total_iterations);
//   for (int i = 0; i < total_iterations; ++i) {
//     step(...);
//     progress.update(i + 1, "iteration");     // cheap: a clock read; prints at most 10 times a second
//   }
//   progress.finish();                          // (the destructor does it too) erases the line
//
// It writes to stderr only, only when stderr is a terminal and only once the run has lasted more
// than a second, so pipes, logs, tests and quick runs stay silent and stdout stays clean for
// JSON. The line shows what is being done, a bar, the percentage, done/total, the elapsed time and
// an estimate of the time left. Not thread-safe: call update() from the thread that drives the loop.
#include <chrono>
#include <cstdio>
#include <string>
#include <string_view>

namespace drape::app {

class Progress {
 public:
  // `total` units of work (iterations, frames); 0 when unknown (no bar, no estimate).
  Progress(std::string task, double total);
  // For tests and special cases: write to `out`, decide yourself whether it is a terminal, and
  // after how many seconds the line may first appear.
  Progress(std::string task, double total, std::FILE* out, bool is_terminal, double quiet_seconds = 1.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // `done` units finished so far; `detail` says what is happening now (e.g. "settling").
  void update(double done, std::string_view detail = {});
  // Erases the line if one was drawn. Idempotent.
  void finish();
  // Whether a progress line is on the terminal now.
  bool shown() const { return shown_; }

 private:
  using Clock = std::chrono::steady_clock;
  void draw(double done, std::string_view detail, double elapsed_s);

  std::string task_;
  double total_;
  std::FILE* out_;
  bool enabled_;
  double quiet_seconds_;
  bool shown_ = false;
  Clock::time_point start_ = Clock::now();
  Clock::time_point last_draw_{};
};

}  // namespace drape::app
