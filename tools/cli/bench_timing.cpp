#include "cli/bench_timing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace batchcol::cli {
namespace {

double seconds_of(const std::function<void()>& call, int calls) {
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < calls; ++k) call();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

CallTiming time_calls(const std::function<void()>& call, int timed_runs, double min_run_seconds) {
  // The warm-up takes the page faults and starts TBB's threads; the second call sizes the runs.
  seconds_of(call, 1);
  CallTiming t;
  if (min_run_seconds > 0) {
    const double one = std::max(seconds_of(call, 1), 1e-7);  // a clock tick is ~20-50 ns; never divide by 0
    // Capped so that a mis-measured first call cannot make the bench run for minutes.
    constexpr double kMaxCalls = 100000;
    t.calls_per_run = static_cast<int>(std::clamp(std::ceil(min_run_seconds / one), 1.0, kMaxCalls));
  }
  std::vector<double> per_call;
  per_call.reserve(timed_runs);
  for (int run = 0; run < timed_runs; ++run) per_call.push_back(seconds_of(call, t.calls_per_run) / t.calls_per_run);
  std::sort(per_call.begin(), per_call.end());
  t.seconds_per_call = per_call.empty() ? 0.0 : per_call[per_call.size() / 2];
  return t;
}

}  // namespace batchcol::cli
