// GoogleTest expectations shared by the FCL and Bullet cross-checks.
#pragma once

#include "crosscheck/crosscheck_runner.hpp"

namespace batchcol::crosscheck {

/// Batchcol's own results are consistent and certified independently of any peer: witness identity and unit
/// normal within 1e-9, witness points on their shapes within 1e-9, separated distances within `certified` of the
/// lower bound certified by batchcol's own normal (and never below it), and roughly half of the pairs on each side.
void expect_batchcol_certified(const RunSummary& s, double certified = 1e-9);

/// Every disagreement with the peer is settled against the peer: batchcol is never proven wrong and nothing stays
/// undecided; at most `max_peer_wrong` of the compared pairs may be proven peer errors or peer failures (more
/// means an adapter bug). Pairs hitting a documented peer bug are only required not to prove batchcol wrong.
void expect_peer_settled(const RunSummary& s, double max_peer_wrong = 0.01);

}  // namespace batchcol::crosscheck
