#include "crosscheck/agreement.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

namespace batchcol::crosscheck {

double ErrorStats::max() const { return errors_.empty() ? 0.0 : *std::max_element(errors_.begin(), errors_.end()); }

double ErrorStats::quantile(double q) const {
  if (errors_.empty()) return 0.0;
  std::vector<double> sorted = errors_;
  const auto k = static_cast<std::size_t>(std::lround(q * static_cast<double>(sorted.size() - 1)));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  return sorted[k];
}

void report(const std::string& label, const std::string& key, const ErrorStats& stats) {
  char line[256];
  std::snprintf(line, sizeof line, "n=%zu max=%.3g median=%.3g p99=%.3g", stats.count(), stats.max(),
                stats.median(), stats.quantile(0.99));
  note(label, line);
  char value[32];
  std::snprintf(value, sizeof value, "%.3g", stats.max());
  ::testing::Test::RecordProperty(key + "_max", value);
  std::snprintf(value, sizeof value, "%.3g", stats.median());
  ::testing::Test::RecordProperty(key + "_median", value);
  ::testing::Test::RecordProperty(key + "_n", static_cast<int>(stats.count()));
}

void note(const std::string& label, const std::string& text) {
  std::cout << "[crosscheck] " << label << ": " << text << std::endl;
}

}  // namespace batchcol::crosscheck
