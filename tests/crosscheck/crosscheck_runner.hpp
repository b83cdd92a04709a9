// Runs a batch of random pairs through batchcol and through a peer library, checks batchcol against the
// independent certificates (certificates.hpp) and compares it with the peer. Every disagreement beyond the
// tolerances is settled by the certificates: the peer is proven wrong, batchcol is proven wrong, or it stays
// undecided. The tests assert that batchcol is never proven wrong and nothing stays undecided; proven peer
// errors are counted and printed (the first few in full) so they stay visible without failing batchcol's suite.
#pragma once

#include "crosscheck/agreement.hpp"
#include "crosscheck/crosscheck_pairs.hpp"
#include "peers/peer_answer.hpp"

#include <functional>
#include <string>
#include <vector>

namespace batchcol::crosscheck {

// The peer adapters live in tools/peers (shared with `batchcol bench`).
using namespace ::batchcol::peers;

using PeerQuery = std::function<PeerAnswer(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb)>;

struct RunConfig {
  std::string label;        // printed before every statistic, e.g. "fcl/libccd cone"
  QueryOptions options;     // batchcol's query (penetration level, tight tolerance)
  PeerQuery peer_collide;   // boolean (may be empty)
  PeerQuery peer_distance;  // signed distance and witness points (may be empty)
  bool peer_depths = true;  // also ask peer_distance for overlapping pairs (FCL's EPA can abort on an assert)
  /// Pairs hitting a documented bug of the peer: returns its description, or nullptr. They are still compared, but
  /// their verdicts are tallied apart (RunSummary::known_bug) so they neither hide nor drown the other results.
  std::function<const char*(const Shape& a, const Pose& pa, const Shape& b, const Pose& pb)> known_peer_bug;
  double band = 1e-6;       // booleans are compared only when |batchcol distance| > band
  double distance_tolerance = 1e-6;  // |batchcol - peer| above this on a separated pair is a disagreement
};

/// A count of disagreements and how the certificates settled them.
struct Verdicts {
  std::size_t compared = 0, disagree = 0, peer_wrong = 0, batchcol_wrong = 0, undecided = 0;
};

struct RunSummary {
  std::size_t pairs = 0, separated = 0, overlapping = 0, peer_failures = 0;
  std::size_t not_converged_separated = 0;    // GJK ran out of iterations
  std::size_t not_converged_overlapping = 0;  // usually EPA's vertex budget on deep curved contacts
  ErrorStats identity;        // |witness_b - witness_a - distance * normal| and ||normal| - 1|, all pairs
  ErrorStats containment;     // distance of batchcol's witness points to their shapes (separated pairs)
  ErrorStats certified_gap;   // batchcol distance - certified lower bound (converged separated pairs)
  ErrorStats depth_gap;       // the same for converged overlapping pairs: EPA's depth against its certificate
  ErrorStats unconverged_gap; // the same for pairs that did not converge
  double min_certified_gap = 0;  // most negative (distance below its certified lower bound: impossible)
  ErrorStats distance_diff;   // |batchcol - peer| on separated pairs, proven peer errors excluded
  ErrorStats depth_diff;      // the same on overlapping pairs (information only)
  ErrorStats peer_error;      // |batchcol - peer| on the pairs where the certificates prove the peer wrong
  Verdicts booleans, distances, depths;
  Verdicts known_bug;          // all comparisons of pairs matching RunConfig::known_peer_bug
  std::string known_bug_description;
  std::vector<std::string> examples;  // descriptions of the first disagreements
};

RunSummary run_crosscheck(const CrossPairs& pairs, const RunConfig& config);

/// Prints the summary (statistics and verdict counts) and the examples.
void print_summary(const std::string& label, const RunSummary& s);

}  // namespace batchcol::crosscheck
