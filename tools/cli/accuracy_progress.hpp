// A one-line progress bar on stderr, drawn only when stderr is a terminal (logs and pipes stay clean).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace batchcol::cli {

class ProgressBar {
 public:
  explicit ProgressBar(std::size_t total);
  ~ProgressBar();
  /// Marks `done` steps finished; `label` names the step under way. Redraws at most 10 times a second.
  void update(std::size_t done, const std::string& label);
  /// Clears the line (call before printing anything else on stderr).
  void finish();

 private:
  std::size_t total_;
  bool enabled_, drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace batchcol::cli
