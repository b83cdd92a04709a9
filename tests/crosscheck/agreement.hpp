// Error statistics for the cross-checks (max, median, 99th percentile of absolute differences) and their report:
// one line on stdout per statistic, also recorded as GoogleTest properties (visible in the XML output).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace batchcol::crosscheck {

class ErrorStats {
 public:
  void add(double abs_error) { errors_.push_back(abs_error); }
  std::size_t count() const { return errors_.size(); }
  double max() const;
  double quantile(double q) const;  // q in [0, 1]; 0 when empty
  double median() const { return quantile(0.5); }

 private:
  std::vector<double> errors_;
};

/// Prints "[crosscheck] <label>: n=... max=... median=... p99=..." and records <key>_max/_median/_n properties.
void report(const std::string& label, const std::string& key, const ErrorStats& stats);

/// Prints "[crosscheck] <label>: <text>" (free-form counts such as boolean agreement).
void note(const std::string& label, const std::string& text);

}  // namespace batchcol::crosscheck
