#include "cli/accuracy_progress.hpp"

#include <cstdio>

#include <unistd.h>

namespace batchcol::cli {

ProgressBar::ProgressBar(std::size_t total)
    : total_(total), enabled_(::isatty(STDERR_FILENO) == 1), start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(std::size_t done, const std::string& label) {
  if (!enabled_ || total_ == 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && done < total_ && now - last_ < std::chrono::milliseconds(100)) return;
  last_ = now;
  constexpr int kWidth = 30;
  const double fraction = double(done) / double(total_);
  const int filled = int(fraction * kWidth);
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double remaining = done > 0 ? elapsed * double(total_ - done) / double(done) : 0.0;
  std::fprintf(stderr, "\r[%.*s%.*s] %zu/%zu  %3.0f%%  ~%.0f s left  %-48.48s", filled,
               "##############################", kWidth - filled, "------------------------------", done, total_,
               100.0 * fraction, remaining, label.c_str());
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (!enabled_ || !drawn_) return;
  std::fprintf(stderr, "\r%*s\r", 120, "");
  std::fflush(stderr);
  drawn_ = false;
}

}  // namespace batchcol::cli
