// One pair, end to end: closed forms where they exist, otherwise GJK (plain / Nesterov / Polyak) on the cores,
// EPA when the cores overlap and depth was asked, then the swept-sphere radii. This scalar code is the reference
// the wide (SIMD) kernels are tested against.
#pragma once

#include "batchcol/batch.hpp"
#include "kernels/pair_output.hpp"

namespace batchcol::kernels {

/// Pose of B's frame in A's frame, in double: computing the relative pose once in double keeps float kernels
/// accurate for shapes far from the world origin.
using RelativePose = Transform<double>;

/// Solves one pair in precision T. `warm_direction` (A's frame) seeds GJK when finite and non-zero.
/// Results are in A's frame.
template <class T>
PairOutput<T> solve_pair(const Shape& a, const Shape& b, const RelativePose& b_in_a,
                         const Eigen::Vector3d& warm_direction, const QueryOptions& options);

/// The smallest distance tolerance precision T can certify for a problem of size `scale` (metres): the requested
/// tolerance is raised to this floor, since support values and |x| are only known to a few ulps of the scale.
template <class T> T tolerance_floor(T scale) { return T(16) * machine_epsilon<T>() * scale; }

extern template PairOutput<double> solve_pair<double>(const Shape&, const Shape&, const RelativePose&,
                                                      const Eigen::Vector3d&, const QueryOptions&);
extern template PairOutput<float> solve_pair<float>(const Shape&, const Shape&, const RelativePose&,
                                                    const Eigen::Vector3d&, const QueryOptions&);

}  // namespace batchcol::kernels
