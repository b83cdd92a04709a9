#include "crosscheck/expectations.hpp"

#include <gtest/gtest.h>

namespace batchcol::crosscheck {

void expect_batchcol_certified(const RunSummary& s, double certified) {
  EXPECT_LE(s.identity.max(), 1e-9) << "witness_b - witness_a != distance * normal (or normal not unit)";
  EXPECT_LE(s.containment.max(), 1e-9) << "a witness point is off its shape";
  EXPECT_LE(s.certified_gap.max(), certified) << "a distance is not certified by batchcol's normal or direction";
  EXPECT_GE(s.min_certified_gap, -1e-12) << "a signed distance is below its certified lower bound";
  EXPECT_LE(s.depth_gap.max(), certified) << "an EPA depth is not certified by batchcol's normal or direction";
  EXPECT_EQ(s.not_converged_separated, 0u) << "GJK did not converge on a separated pair";
  EXPECT_LE(s.not_converged_overlapping, s.pairs / 1000) << "EPA ran out of budget on many pairs";
  EXPECT_GE(s.separated, s.pairs / 4) << "the sampler should give about as many separated as overlapping pairs";
  EXPECT_GE(s.overlapping, s.pairs / 4) << "the sampler should give about as many overlapping as separated pairs";
}

void expect_peer_settled(const RunSummary& s, double max_peer_wrong) {
  EXPECT_EQ(s.known_bug.batchcol_wrong, 0u) << "the certificates prove batchcol wrong (see the examples above)";
  for (const Verdicts* v : {&s.booleans, &s.distances, &s.depths}) {
    EXPECT_EQ(v->batchcol_wrong, 0u) << "the certificates prove batchcol wrong (see the examples above)";
    EXPECT_LE(static_cast<double>(v->peer_wrong), max_peer_wrong * static_cast<double>(v->compared));
  }
  EXPECT_EQ(s.booleans.undecided, 0u) << "a boolean disagreement the certificates cannot settle";
  EXPECT_EQ(s.distances.undecided, 0u) << "a distance disagreement the certificates cannot settle";
  EXPECT_LE(static_cast<double>(s.peer_failures), max_peer_wrong * static_cast<double>(s.pairs))
      << "the peer failed or threw on many pairs";
}

}  // namespace batchcol::crosscheck
