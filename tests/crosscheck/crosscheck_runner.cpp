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
/// Pairs whose certified interval is wider than this are printed as examples.
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
  double lower;                  // certified lower bound from batchcol's normal
  double upper;                  // certified upper bound (separated: witness distance + containment), else +inf
  bool known_bug = false;        // the pair hits a documented peer bug (RunConfig::known_peer_bug)
};

/// Batchcol's witness points, their midpoint and the quarter points: one proving the overlap settles it.
bool overlap_proven(const PairState& p) {
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
  o << what << " (pair " << p.index << ", status " << to_string(p.status) << "): a=" << describe(p.a) << " " << describe(p.pa) << "; b=" << describe(p.b)
    << " " << describe(p.pb) << "; batchcol d=" << p.distance << " peer d=" << peer.distance
    << " peer collide=" << peer.collide << " certified [" << p.lower << ", " << p.upper << "]";
  s.examples.push_back(o.str());
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
  if (separated ? p.lower > 0 : overlap_proven(p)) {
    ++v.peer_wrong;
  } else if (!separated && peer_proves_separation()) {
    ++v.batchcol_wrong;
  } else {
    ++v.undecided;
  }
  add_example(s, p.known_bug ? "known peer bug, boolean disagreement" : "boolean disagreement", p, peer);
}

/// Settles |batchcol - peer| > tolerance for a signed distance with the certified interval [lower, upper].
void settle_distance(RunSummary& s, Verdicts& v, const RunConfig& c, const PairState& p, const PeerAnswer& peer,
                     const char* what) {
  ++v.disagree;
  const double lower = std::max(p.lower, peer_lower_bound(p, peer));
  const bool batchcol_out = p.distance < lower - kRounding || p.distance > p.upper + kRounding;
  const bool peer_out = peer.distance < lower - kRounding || peer.distance > p.upper + kRounding;
  if (batchcol_out) ++v.batchcol_wrong;
  else if (peer_out) ++v.peer_wrong;
  else ++v.undecided;
  add_example(s, std::string(p.known_bug ? "known peer bug, " : "") + what + " disagreement", p, peer);
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
  if (!p.known_bug) (separated ? s.distance_diff : s.depth_diff).add(diff);
  // Even within the tolerance, a peer direction certifying more than batchcol's distance proves batchcol wrong.
  const bool disproved = peer_lower_bound(p, peer) > p.distance + c.distance_tolerance;
  if (diff > c.distance_tolerance || disproved) settle_distance(s, v, c, p, peer, separated ? "distance" : "depth");
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
    if (r.status[i] != Status::converged) ++s.not_converged;
    s.identity.add(std::max((p.wb - p.wa - p.distance * p.normal).norm(), std::abs(p.normal.norm() - 1.0)));
    // Batchcol certifies its distance with its last support direction (world frame, D = A - B, so pointing from
    // b to a); the reported normal is the direction of the closest point, usually as good. Both bound it.
    const Eigen::Vector3d direction = r.direction[i];
    p.lower = certified_lower_bound(a, p.pa, b, p.pb, p.normal);
    if (direction.allFinite() && direction.norm() > 0)
      p.lower = std::max(p.lower, certified_lower_bound(a, p.pa, b, p.pb, -direction));
    if (p.distance - p.lower > kRefineAbove) p.lower = refined_lower_bound(a, p.pa, b, p.pb, p.normal);
    if (p.distance > 0) {
      ++s.separated;
      const double ca = std::max(signed_outside(a, p.pa, p.wa), 0.0), cb = std::max(signed_outside(b, p.pb, p.wb), 0.0);
      s.containment.add(std::max(ca, cb));
      p.upper = (p.wb - p.wa).norm() + ca + cb;
      s.certified_gap.add(std::max(p.distance - p.lower, 0.0));
    } else {
      ++s.overlapping;
      s.depth_gap.add(std::max(p.distance - p.lower, 0.0));
    }
    s.min_certified_gap = std::min(s.min_certified_gap, p.distance - p.lower);
    if (p.distance - p.lower > kCertifiedReportAbove)
      add_example(s, p.distance > 0 ? "batchcol distance not certified by its normal"
                                     : "batchcol depth not certified by its normal", p, PeerAnswer{});
    if (c.peer_collide) compare_boolean(s, c, p);
    if (c.peer_distance) compare_distance(s, c, p);
  }
  return s;
}

void print_summary(const std::string& label, const RunSummary& s) {
  char line[256];
  std::snprintf(line, sizeof line, "%zu pairs, %zu separated, %zu overlapping, %zu not converged, %zu peer failures",
                s.pairs, s.separated, s.overlapping, s.not_converged, s.peer_failures);
  note(label, line);
  report(label + " batchcol witness identity", "identity", s.identity);
  report(label + " batchcol witness containment", "containment", s.containment);
  report(label + " batchcol distance - certified lower bound", "certified_gap", s.certified_gap);
  report(label + " batchcol depth - certified lower bound", "depth_gap", s.depth_gap);
  report(label + " |batchcol - peer| distance", "distance_diff", s.distance_diff);
  report(label + " |batchcol - peer| depth (info)", "depth_diff", s.depth_diff);
  const auto verdicts = [&](const char* name, const Verdicts& v) {
    std::snprintf(line, sizeof line,
                  "compared %zu, disagree %zu: peer proven wrong %zu, batchcol proven wrong %zu, undecided %zu",
                  v.compared, v.disagree, v.peer_wrong, v.batchcol_wrong, v.undecided);
    note(label + " " + name, line);
  };
  verdicts("booleans", s.booleans);
  verdicts("distances", s.distances);
  verdicts("depths (info)", s.depths);
  if (s.known_bug.compared > 0) verdicts(("pairs hitting a known peer bug (" + s.known_bug_description + ")").c_str(), s.known_bug);
  for (const auto& e : s.examples) note(label, e);
}

}  // namespace batchcol::crosscheck
