// Timing of `batchcol bench`, shared by batchcol and the peers so that both are measured the same way: one warm-up
// call, then each timed run repeats the call until the run lasts at least a minimum time, and the median over the
// runs of (run time / calls) is reported. A single call on 20000 closed-form pairs takes ~0.1 ms on 2 threads, short
// enough that TBB's thread wake-ups and a noisy VM change it 2.5x between invocations; longer runs average that out.
#pragma once

#include <functional>

namespace batchcol::cli {

struct CallTiming {
  double seconds_per_call = 0;  // median over the timed runs of run time / calls per run
  int calls_per_run = 1;        // chosen after the warm-up from the minimum run time
};

/// `call` must do the same work every time. min_run_seconds <= 0 times one call per run.
CallTiming time_calls(const std::function<void()>& call, int timed_runs, double min_run_seconds);

}  // namespace batchcol::cli
