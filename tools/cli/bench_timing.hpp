// Timing of `batchcol bench`, shared by batchcol and the peers so that both are measured the same way: one warm-up
// call; then the number of calls per run grows until one batch of calls lasts a minimum time; every timed run makes
// that many calls, and the median over the runs of (run time / calls) is reported. A single call on 20000
// closed-form pairs takes ~0.15 ms on 2 threads, short enough that TBB's thread wake-ups and a noisy VM changed it
// 2.5x between invocations; batches of calls average that out.
#pragma once

#include <functional>
#include <vector>

namespace batchcol::cli {

struct CallTiming {
  double seconds_per_call = 0;  // median over the timed runs of run time / calls per run
  int calls_per_run = 1;        // the smallest count tried whose batch lasted the minimum time (or the cap)
};

/// `call` must do the same work every time. min_run_seconds <= 0 times one call per run.
CallTiming time_calls(const std::function<void()>& call, int timed_runs, double min_run_seconds);

/// The upper median (v[size / 2] of the sorted values); 0 for none.
double median_of(std::vector<double> v);

}  // namespace batchcol::cli
