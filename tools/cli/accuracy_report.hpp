// Outputs of `batchcol accuracy`: accuracy.csv (one row per case x regime x solver x precision x tolerance) and
// summary.md (the "done when" check, the cheapest configuration per error level, iterations per regime).
#pragma once

#include "cli/accuracy_measure.hpp"

#include <iosfwd>
#include <string>
#include <vector>

namespace batchcol::cli {

/// The CSV header, column names separated by commas (tests and tools/plot_accuracy.py read columns by name).
extern const char* const kAccuracyCsvHeader;

void write_accuracy_csv(const std::vector<AccuracyRow>& rows, std::ostream& out);

/// Run settings echoed at the top of summary.md.
struct SummaryContext {
  std::string command;  // the command line that produced the report
  std::size_t pairs = 0;
  int threads = 0, runs = 0, max_iterations = 0;
};

/// Error levels of the summary's "cheapest configuration" table, and the thresholds.
constexpr double kSummaryLevels[] = {1e-3, 1e-6, 1e-9};
constexpr double kDoubleTarget = 1e-9;         // max |distance error|, metres
constexpr double kFloatRelativeTarget = 1e-5;  // max |distance error| / scale (CaseData::scale)

void write_accuracy_summary(const std::vector<AccuracyRow>& rows, const SummaryContext& context, std::ostream& out);

}  // namespace batchcol::cli
