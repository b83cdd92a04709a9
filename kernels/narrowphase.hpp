// One pair, end to end: closed forms where they exist, otherwise GJK (plain / Nesterov / Polyak) on the cores,
// EPA when the cores overlap and depth was asked, then the swept-sphere radii. This scalar code is the reference
// the wide (SIMD) kernels are tested against.
#pragma once

#include "batchcol/types.hpp"
#include "kernels/gjk.hpp"
#include "kernels/pair_output.hpp"

namespace batchcol::kernels {

/// Pose of B's frame in A's frame, in double: computing the relative pose once in double keeps float kernels
/// accurate for shapes far from the world origin.
using RelativePose = Transform<double>;

/// Solves one pair in precision T. `warm_direction` (A's frame) seeds GJK when finite and non-zero.
/// Results are in A's frame. Shapes come as plain views (batchcol/types.hpp); a convex one's hull view must outlive
/// the call (and, for setup_pair*, the setup, whose cores point to it).
template <class T>
PairOutput<T> solve_pair(const ShapeView& a, const ShapeView& b, const RelativePose& b_in_a,
                         const Eigen::Vector3d& warm_direction, const QueryOptions& options);

/// Everything GJK needs for one pair, prepared once: the cores, B's pose in A's frame in precision T, the
/// parameters and the first direction. `done` means a closed form already answered (`out`). The scalar path and
/// the wide (SIMD) kernels share this setup and complete_pair(), so they differ only in how GJK itself runs.
template <class T> struct PairSetup {
  ShapeCore<T> A, B;
  Transform<T> X;
  GjkParams<T> params;
  T radii = T(0), scale = T(0), floor = T(0);
  Vec3<T> initial_direction = Vec3<T>::UnitX();
  bool done = false;
  PairOutput<T> out;

  MinkowskiDifference<T> difference() const { return MinkowskiDifference<T>{&A, &B, X, {}, {}}; }
};

template <class T>
PairSetup<T> setup_pair(const ShapeView& a, const ShapeView& b, const RelativePose& b_in_a,
                        const Eigen::Vector3d& warm_direction, const QueryOptions& options);
/// setup_pair() written into `s` (the executor's hot path: no 0.5 KB temporary copied per pair). `s.out` is set
/// only when `s.done`.
template <class T>
void setup_pair_into(const ShapeView& a, const ShapeView& b, const RelativePose& b_in_a,
                     const Eigen::Vector3d& warm_direction,
                     const QueryOptions& options, PairSetup<T>& s);
/// Whether setup_pair_into() may answer a pair of types (a, b) by a closed form under `options` (closed_form()
/// beside it, and the box-box separating-axis test, which also needs plain boxes). Pairs of other type pairs
/// always run GJK.
bool may_have_closed_form(ShapeType a, ShapeType b, const QueryOptions& options);
/// What completing a pair needs of its setup when GJK's ending needs no cores (see complete_from_gjk).
template <class T> struct GjkCompletion {
  T radius_a = T(0), radius_b = T(0);  // swept radii of A and B
  T radii = T(0), scale = T(0), floor = T(0), tolerance = T(0), core_margin = T(0);  // as in PairSetup
};
/// complete_pair() for every GJK ending that needs no cores, written into `out`; returns false (and the caller
/// runs complete_pair on the full setup) for overlapping cores at QueryLevel::penetration (EPA), for a float
/// stall above 2 precision floors (redone in double) and for a double stall above what the arithmetic certifies
/// (`out` is then the degenerate answer, which complete_pair() replaces by a closed form where one applies).
/// complete_pair() itself starts with this function, so both give the same bits.
template <class T>
bool complete_from_gjk(const GjkCompletion<T>& c, const GjkResult<T>& g, const QueryOptions& options,
                       PairOutput<T>& out);
/// From GJK's result to the pair's answer: EPA when the cores overlap and depth was asked, the swept radii, the
/// stall acceptance (a float stall above 2 precision floors is solved again in double) and the conservative
/// `collide`.
template <class T>
PairOutput<T> complete_pair(const PairSetup<T>& setup, const GjkResult<T>& gjk, const QueryOptions& options);

/// The smallest distance tolerance precision T can certify for a problem of size `scale` (metres): the requested
/// tolerance is raised to this floor, since support values and |x| are only known to a few ulps of the scale.
template <class T> T tolerance_floor(T scale) { return T(16) * machine_epsilon<T>() * scale; }

/// A pair's GJK numbers from plain values: swept radii, scale (bounding radii of A and B plus |t|, in double),
/// precision floor, tolerances, margin. The one place they are computed: set_gjk_parameters() (the per-pair
/// setup) and the batch-array GJK's lean lane setup (simd/wide_gjk_pairs.inl) both call it, so their bits agree.
template <class T> struct GjkLimits {
  T radii, scale, floor, tolerance, relative, core_margin, touch;
  int max_iterations;
  bool boolean_only;
};
template <class T>
GjkLimits<T> gjk_limits(T radius_a, T radius_b, double bounding_a, double bounding_b, double t_norm,
                        const QueryOptions& opt) {
  GjkLimits<T> g;
  g.radii = radius_a + radius_b;
  g.scale = T(bounding_a + bounding_b + t_norm);
  g.floor = tolerance_floor(g.scale);
  g.tolerance = std::max(T(opt.tolerance), g.floor);
  g.relative = T(opt.relative_tolerance);
  g.max_iterations = opt.max_iterations;
  g.boolean_only = opt.level == QueryLevel::boolean;
  g.core_margin = T(opt.margin) + g.radii;
  g.touch = g.floor;  // 16 ulps of the problem size
  return g;
}

/// The rest of a GJK setup once its cores and relative pose X are set: gjk_limits(), the solver, the momentum
/// normalisation and the first direction (`warm` when finite and non-zero, else the centre difference).
template <class T>
void set_gjk_parameters(PairSetup<T>& s, double bounding_a, double bounding_b, double t_norm,
                        const Vec3<T>& warm, const QueryOptions& opt) {
  const GjkLimits<T> g = gjk_limits(s.A.radius, s.B.radius, bounding_a, bounding_b, t_norm, opt);
  s.radii = g.radii;
  s.scale = g.scale;
  s.floor = g.floor;
  GjkParams<T>& params = s.params;
  params.solver = resolve_solver(opt.solver, opt.level, s.A.type, s.B.type);
  params.tolerance = g.tolerance;
  params.relative_tolerance = g.relative;
  params.max_iterations = g.max_iterations;
  params.boolean_only = g.boolean_only;
  params.core_margin = g.core_margin;
  params.normalize_momentum = !(s.A.strictly_convex() && s.B.strictly_convex());
  params.touch_tolerance = g.touch;
  const bool use_warm = warm.allFinite() && warm.squaredNorm() > T(0);
  s.initial_direction = use_warm ? warm : s.difference().center();
}

extern template PairOutput<double> solve_pair<double>(const ShapeView&, const ShapeView&, const RelativePose&,
                                                      const Eigen::Vector3d&, const QueryOptions&);
extern template PairOutput<float> solve_pair<float>(const ShapeView&, const ShapeView&, const RelativePose&,
                                                    const Eigen::Vector3d&, const QueryOptions&);
extern template bool complete_from_gjk<double>(const GjkCompletion<double>&, const GjkResult<double>&,
                                                const QueryOptions&, PairOutput<double>&);
extern template bool complete_from_gjk<float>(const GjkCompletion<float>&, const GjkResult<float>&,
                                               const QueryOptions&, PairOutput<float>&);
extern template void setup_pair_into<double>(const ShapeView&, const ShapeView&, const RelativePose&,
    const Eigen::Vector3d&, const QueryOptions&, PairSetup<double>&);
extern template void setup_pair_into<float>(const ShapeView&, const ShapeView&, const RelativePose&,
    const Eigen::Vector3d&, const QueryOptions&, PairSetup<float>&);
extern template PairSetup<double> setup_pair<double>(const ShapeView&, const ShapeView&, const RelativePose&,
                                                     const Eigen::Vector3d&, const QueryOptions&);
extern template PairSetup<float> setup_pair<float>(const ShapeView&, const ShapeView&, const RelativePose&,
                                                   const Eigen::Vector3d&, const QueryOptions&);
extern template PairOutput<double> complete_pair<double>(const PairSetup<double>&, const GjkResult<double>&,
                                                         const QueryOptions&);
extern template PairOutput<float> complete_pair<float>(const PairSetup<float>&, const GjkResult<float>&,
                                                       const QueryOptions&);

}  // namespace batchcol::kernels
