#include "crosscheck/crosscheck_runner.hpp"

#include "crosscheck/certificates.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

namespace batchcol::crosscheck {
namespace {

constexpr std::size_t kMaxExamplesPerKind = 3;
/// Slack for rounding when comparing a distance with a certificate computed along a different code path
/// (a few ulps of the 1 m scale of the scenes).
constexpr double kRounding = 1e-12;
/// Lower bounds further than this below batchcol's distance are tightened by a local search (refined_lower_bound).
constexpr double kRefineAbove = 1e-10;
/// Pairs whose distance is further than this above its certified lower bound are printed as examples.
constexpr double kCertifiedReportAbove = 1e-8;

std::string describe(const Shape& s) {
  std::ostringstream o;
  o.precision(17);
  o << to_string(s.type);
  switch (s.type) {
    case ShapeType::convex: o << "(" << s.hull->vertices.size() << " vertices)"; break;
    case ShapeType::triangle:
      for (const auto& v : s.triangle) o << " [" << v.transpose() << "]";
      break;
    case ShapeType::halfspace: o << " n=[" << s.size.transpose() << "] offset=" << s.offset; break;
    default: o << " size=[" << s.size.transpose() << "]"; break;
  }
  return o.str();
}

std::string describe(const Pose& p) {
  std::ostringstream o;
  o.precision(17);
  const auto& q = p.rotation;
  o << "t=[" << p.translation.transpose() << "] q=[" << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << "]";
  return o.str();
}

/// The pair as seen by both sides, with batchcol's result and its certificates.
struct PairState {
  std::size_t index;
  const Shape& a;
  Pose pa;
  const Shape& b;
  Pose pb;
  Status status;                 // batchcol
  double distance;               // batchcol
  Eigen::Vector3d wa, wb, normal;  // batchcol
  double lower;                  // certified lower bound (batchcol normal, direction, local search)
  double upper;                  // certified upper bound (separated: witness distance + containment), else +inf
  bool known_bug = false;        // the pair hits a documented peer bug (RunConfig::known_peer_bug)
};

/// Batchcol's witness points, their midpoint and the quarter points: one proving the overlap settles it (two
/// triangles: an edge crossing the other triangle).
bool overlap_proven(const PairState& p) {
  if (triangles_cross(p.a, p.pa, p.b, p.pb)) return true;
  for (double t : {0.0, 0.25, 0.5, 0.75, 1.0})
    if (proves_overlap(p.a, p.pa, p.b, p.pb, p.wa + t * (p.wb - p.wa))) return true;
  return false;
}

/// Lower bound certified by the peer's witness direction, or -inf when the peer gave none.
double peer_lower_bound(const PairState& p, const PeerAnswer& peer) {
  const Eigen::Vector3d delta = peer.point_b - peer.point_a;
  if (!delta.allFinite() || delta.norm() == 0.0 || !std::isfinite(peer.distance) || peer.distance == 0.0)
    return -std::numeric_limits<double>::infinity();
  // witness_b - witness_a = distance * normal, so normal = delta / distance for either sign.
  return certified_lower_bound(p.a, p.pa, p.b, p.pb, delta / peer.distance);
}

void add_example(RunSummary& s, const std::string& what, const PairState& p, const PeerAnswer& peer) {
  const std::size_t same_kind = static_cast<std::size_t>(std::count_if(
      s.examples.begin(), s.examples.end(), [&](const std::string& e) { return e.rfind(what, 0) == 0; }));
  if (same_kind >= kMaxExamplesPerKind) return;
  std::ostringstream o;
  o.precision(17);
  o << what << " (pair " << p.index << ", status " << to_string(p.status) << "): a=" << describe(p.a) << " "
    << describe(p.pa) << "; b=" << describe(p.b) << " " << describe(p.pb) << "; batchcol d=" << p.distance
    << " peer d=" << peer.distance
    << " peer collide=" << peer.collide << " certified [" << p.lower << ", " << p.upper << "]";
  s.examples.push_back(o.str());
}

/// Upper bound on the distance from batchcol's witness points x: dist(x, a) + dist(x, b).
double witness_upper_bound(const PairState& p) {
  double upper = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& x : {p.wa, p.wb})
    upper = std::min(upper, std::max(signed_outside(p.a, p.pa, x), 0.0) + std::max(signed_outside(p.b, p.pb, x), 0.0));
  return upper;
}

/// The peer claims a positive distance (in its boolean answer or, failing that, from its distance query) that an
/// overlap proof or the witness upper bound refutes.
bool peer_distance_refuted(const RunConfig& c, const PairState& p, const PeerAnswer& answer) {
  double claimed = answer.distance;
  if (!std::isfinite(claimed) && c.peer_distance) claimed = c.peer_distance(p.a, p.pa, p.b, p.pb).distance;
  return claimed > 0 && (overlap_proven(p) || claimed > witness_upper_bound(p) + kRounding);
}

void compare_boolean(RunSummary& s, const RunConfig& c, const PairState& p) {
  if (std::abs(p.distance) <= c.band) return;
  const PeerAnswer peer = c.peer_collide(p.a, p.pa, p.b, p.pb);
  if (!peer.ok) { ++s.peer_failures; return; }
  Verdicts& v = p.known_bug ? s.known_bug : s.booleans;
  ++v.compared;
  const bool separated = p.distance > 0;
  if (peer.collide != separated) return;  // agreement
  ++v.disagree;
  // A separation is proven by a direction with a positive lower bound (batchcol's normal, or the peer's witness
  // direction when the peer also computes distances), an overlap by a common point.
  const auto peer_proves_separation = [&] {
    return c.peer_distance && peer_lower_bound(p, c.peer_distance(p.a, p.pa, p.b, p.pb)) > 0;
  };
  if (separated ? p.lower > 0 : overlap_proven(p) || peer_distance_refuted(c, p, peer)) {
    ++v.peer_wrong;
  } else if (!separated && peer_proves_separation()) {
    ++v.batchcol_wrong;
  } else {
    ++v.undecided;
  }
  add_example(s, p.known_bug ? "known peer bug, boolean disagreement" : "boolean disagreement", p, peer);
}

/// For an overlapping pair, the peer claims that translating b by its depth along its normal separates the shapes.
/// A point common to a and the translated b (slightly further) refutes that claim.
bool peer_translation_refuted(const PairState& p, const PeerAnswer& peer) {
  const Eigen::Vector3d delta = peer.point_b - peer.point_a;
  if (!(peer.distance < 0) || !delta.allFinite() || delta.norm() == 0.0) return false;
  const Eigen::Vector3d normal = delta / peer.distance;  // from a to b
  Pose moved = p.pb;
  moved.translation += (-peer.distance + 1e-9) * normal;
  const Eigen::Vector3d shift = moved.translation - p.pb.translation;
  // Candidates: along batchcol's witness segment (b's end moved too) and between the shape origins.
  for (int k = 0; k <= 8; ++k) {
    const double t = k / 8.0;
    if (proves_overlap(p.a, p.pa, p.b, moved, p.wa + t * (p.wb + shift - p.wa)) ||
        proves_overlap(p.a, p.pa, p.b, moved, p.pa.translation + t * (moved.translation - p.pa.translation)))
      return true;
  }
  return false;
}

/// Settles |batchcol - peer| > tolerance for a signed distance with the certified interval [lower, upper].
/// Returns true when the peer is proven wrong.
bool settle_distance(RunSummary& s, Verdicts& v, const PairState& p, const PeerAnswer& peer, const char* what) {
  ++v.disagree;
  const double lower = std::max(p.lower, peer_lower_bound(p, peer));
  const bool batchcol_out = p.distance < lower - kRounding || p.distance > p.upper + kRounding;
  const bool peer_out =
      peer.distance < lower - kRounding || peer.distance > p.upper + kRounding ||
      (p.distance < 0 && (peer_translation_refuted(p, peer) ||
                          (peer.distance > 0 && (overlap_proven(p) || peer.distance > witness_upper_bound(p)))));
  if (batchcol_out) ++v.batchcol_wrong;
  else if (peer_out) ++v.peer_wrong;
  else ++v.undecided;
  add_example(s, std::string(p.known_bug ? "known peer bug, " : "") + what + " disagreement", p, peer);
  return !batchcol_out && peer_out;
}

void compare_distance(RunSummary& s, const RunConfig& c, const PairState& p) {
  if (std::abs(p.distance) <= c.band || (p.distance < 0 && !c.peer_depths)) return;
  const PeerAnswer peer = c.peer_distance(p.a, p.pa, p.b, p.pb);
  if (!peer.ok) { ++s.peer_failures; return; }
  if (!std::isfinite(peer.distance)) return;  // e.g. FCL computes no depth with triangles or its own GJK
  const bool separated = p.distance > 0;
  Verdicts& v = p.known_bug ? s.known_bug : separated ? s.distances : s.depths;
  ++v.compared;
  const double diff = std::abs(p.distance - peer.distance);
  // Even within the tolerance, a peer direction certifying more than batchcol's distance proves batchcol wrong.
  const bool disproved = peer_lower_bound(p, peer) > p.distance + c.distance_tolerance;
  const bool peer_wrong = (diff > c.distance_tolerance || disproved) &&
                          settle_distance(s, v, p, peer, separated ? "distance" : "depth");
  if (p.known_bug) return;
  (peer_wrong ? s.peer_error : separated ? s.distance_diff : s.depth_diff).add(diff);
}

}  // namespace

RunSummary run_crosscheck(const CrossPairs& pairs, const RunConfig& c) {
  RunSummary s;
  PairResults r;
  collide(pairs.shapes, pairs.batch, c.options, r);
  s.pairs = r.size();
  s.min_certified_gap = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < r.size(); ++i) {
    const Shape& a = pairs.shapes[pairs.batch.shape_a[i]];
    const Shape& b = pairs.shapes[pairs.batch.shape_b[i]];
    PairState p{i, a, pairs.batch.pose_a(i), b, pairs.batch.pose_b(i), r.status[i], r.distance[i], r.witness_a[i],
                r.witness_b[i], r.normal[i], 0.0, std::numeric_limits<double>::infinity()};
    if (c.known_peer_bug) {
      if (const char* bug = c.known_peer_bug(a, p.pa, b, p.pb)) {
        p.known_bug = true;
        s.known_bug_description = bug;
      }
    }
    const bool converged = r.status[i] == Status::converged;
    if (!converged) ++(p.distance > 0 ? s.not_converged_separated : s.not_converged_overlapping);
    s.identity.add(std::max((p.wb - p.wa - p.distance * p.normal).norm(), std::abs(p.normal.norm() - 1.0)));
    // Batchcol certifies its distance with its last support direction (world frame, D = A - B, so pointing from
    // b to a); the reported normal is the direction of the closest point, usually as good. Both bound it.
    Eigen::Vector3d best = p.normal;
    p.lower = certified_lower_bound(a, p.pa, b, p.pb, p.normal);
    const Eigen::Vector3d direction = -Eigen::Vector3d(r.direction[i]);
    if (direction.allFinite() && direction.norm() > 0) {
      const double lower = certified_lower_bound(a, p.pa, b, p.pb, direction);
      if (lower > p.lower) { p.lower = lower; best = direction; }
    }
    if (p.distance - p.lower > kRefineAbove) p.lower = refined_lower_bound(a, p.pa, b, p.pb, best);
    if (p.distance > 0) {
      ++s.separated;
      const double ca = std::max(signed_outside(a, p.pa, p.wa), 0.0);
      const double cb = std::max(signed_outside(b, p.pb, p.wb), 0.0);
      s.containment.add(std::max(ca, cb));
      p.upper = (p.wb - p.wa).norm() + ca + cb;
    } else {
      ++s.overlapping;
    }
    const double gap = std::max(p.distance - p.lower, 0.0);
    (!converged ? s.unconverged_gap : p.distance > 0 ? s.certified_gap : s.depth_gap).add(gap);
    s.min_certified_gap = std::min(s.min_certified_gap, p.distance - p.lower);
    if (p.distance - p.lower > kCertifiedReportAbove)
      add_example(s, p.distance > 0 ? "batchcol distance loosely certified" : "batchcol depth loosely certified", p,
                  PeerAnswer{});
    if (c.peer_collide) compare_boolean(s, c, p);
    if (c.peer_distance) compare_distance(s, c, p);
  }
  return s;
}

void print_summary(const std::string& label, const RunSummary& s) {
  char line[256];
  std::snprintf(line, sizeof line,
                "%zu pairs: %zu separated (%zu not converged), %zu overlapping (%zu not converged); %zu peer failures",
                s.pairs, s.separated, s.not_converged_separated, s.overlapping, s.not_converged_overlapping,
                s.peer_failures);
  note(label, line);
  report(label + " batchcol witness identity", "identity", s.identity);
  report(label + " batchcol witness containment", "containment", s.containment);
  report(label + " batchcol distance - certified lower bound", "certified_gap", s.certified_gap);
  report(label + " batchcol depth - certified lower bound", "depth_gap", s.depth_gap);
  if (s.unconverged_gap.count() > 0)
    report(label + " batchcol not converged: result - certified lower bound", "unconverged_gap", s.unconverged_gap);
  report(label + " |batchcol - peer| distance", "distance_diff", s.distance_diff);
  report(label + " |batchcol - peer| depth (info)", "depth_diff", s.depth_diff);
  if (s.peer_error.count() > 0) report(label + " |batchcol - peer| on proven peer errors", "peer_error", s.peer_error);
  const auto verdicts = [&](const char* name, const Verdicts& v) {
    std::snprintf(line, sizeof line,
                  "compared %zu, disagree %zu: peer proven wrong %zu, batchcol proven wrong %zu, undecided %zu",
                  v.compared, v.disagree, v.peer_wrong, v.batchcol_wrong, v.undecided);
    note(label + " " + name, line);
  };
  verdicts("booleans", s.booleans);
  verdicts("distances", s.distances);
  verdicts("depths (info)", s.depths);
  if (s.known_bug.compared > 0)
    verdicts(("pairs hitting a known peer bug (" + s.known_bug_description + ")").c_str(), s.known_bug);
  for (const auto& e : s.examples) note(label, e);
}

}  // namespace batchcol::crosscheck
