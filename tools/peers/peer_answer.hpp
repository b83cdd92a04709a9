// What a peer library (FCL, Bullet) answered for one pair, in batchcol's conventions: world frame, signed distance
// negative when overlapping, normal from a to b.
#pragma once

#include <Eigen/Core>

#include <limits>

namespace batchcol::peers {

struct PeerAnswer {
  bool ok = false;       // the peer handled the pair (false: unsupported pair, failure or exception)
  bool collide = false;  // meaningful for boolean queries
  double distance = std::numeric_limits<double>::quiet_NaN();  // signed; NaN when not computed
  Eigen::Vector3d point_a = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d point_b = point_a;
};

}  // namespace batchcol::peers
