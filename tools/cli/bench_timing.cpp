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
  seconds_of(call, 1);  // warm-up: page faults, TBB's threads
  CallTiming t;
  if (min_run_seconds > 0) {
    // Calls per run: a call of a few ns would need millions, which the cap stops (such runs last less than the
    // minimum). Each step scales the count by the time still missing (x1.2 to x10).
    constexpr double kMaxCalls = 100000;
    double calls = 1, seconds = seconds_of(call, 1);
    while (seconds < min_run_seconds && calls < kMaxCalls) {
      const double grow = seconds > 0 ? 1.2 * min_run_seconds / seconds : 10.0;  // 0: below the clock's tick
      calls = std::min(kMaxCalls, std::ceil(calls * std::clamp(grow, 1.2, 10.0)));
      seconds = seconds_of(call, static_cast<int>(calls));
    }
    t.calls_per_run = static_cast<int>(calls);
  }
  std::vector<double> per_call;
  per_call.reserve(timed_runs);
  for (int run = 0; run < timed_runs; ++run) per_call.push_back(seconds_of(call, t.calls_per_run) / t.calls_per_run);
  t.seconds_per_call = median_of(per_call);
  return t;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace batchcol::cli
