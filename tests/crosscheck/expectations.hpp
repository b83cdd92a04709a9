// GoogleTest expectations shared by the FCL and Bullet cross-checks.
#pragma once

#include "crosscheck/crosscheck_runner.hpp"

namespace batchcol::crosscheck {

/// Batchcol's own results are consistent and certified independently of any peer:
///  - witness identity and unit normal within 1e-9, witness points on their shapes within 1e-9;
///  - every converged distance and EPA depth within `certified` of the lower bound certified by batchcol's own
///    normal or support direction, and never below it. The default 1e-7 bounds how well the reported normal
///    certifies the distance, which is looser than the distance itself: GJK certifies its distance to the
///    tolerance with the best support direction of the run, and a normal off by an angle t moves the bound by
///    ~t times the size of the contact feature (measured: up to ~1e-8 at tolerance 1e-10);
///  - every separated pair converged; EPA may run out of vertices on at most 0.1% of the pairs (deep contacts of
///    curved shapes at this tolerance);
///  - at least a quarter of the pairs on each side of contact (the sampler aims at half).
void expect_batchcol_certified(const RunSummary& s, double certified = 1e-7);

/// Every disagreement with the peer is settled against the peer: batchcol is never proven wrong and nothing stays
/// undecided; at most `max_peer_wrong` of the compared pairs may be proven peer errors or peer failures (more
/// means an adapter bug). Pairs hitting a documented peer bug are only required not to prove batchcol wrong.
void expect_peer_settled(const RunSummary& s, double max_peer_wrong = 0.01);

}  // namespace batchcol::crosscheck
