// Entry points of the SIMD closed forms: pairs of one shape-pair type answered W at a time straight from the
// batch's SoA arrays into the results' (no per-pair setup), compiled once per instruction set (isa_*.cpp).
#pragma once

#include "kernels/simd/pair_views.hpp"

#include <cstddef>
#include <cstdint>

namespace batchcol::kernels::simd {

/// Sphere/capsule pairs (every pair of pairs[0 .. n) has A of type capsule when `capsule_a`, else sphere, and
/// likewise B; `pairs` ascending). Writes status, collide and what `query.level` asks (distance, witness points,
/// normal) for the pairs it answers, NaN / 0 in every other result field; returns how many it left to the scalar
/// path (which writes every field of those), their indices in
/// fallback[0 .. count) (invalid input, or touching cores). Results are the same for every instruction set.
std::size_t segment_pairs(InstructionSet isa, const PairView& in, bool capsule_a, bool capsule_b,
                          const std::uint32_t* pairs, std::size_t n, const ClosedFormQuery& query,
                          const ResultView& out, std::uint32_t* fallback);

/// Box-box pairs (all of pairs[0 .. n), ascending) at QueryLevel::boolean with a zero margin: separating-axis
/// test, writes status and collide (NaN / 0 in every other result field); returns how many it left to the scalar
/// path (inflated boxes, invalid input),
/// their indices in fallback[0 .. count).
std::size_t box_pairs_boolean(InstructionSet isa, const PairView& in, const std::uint32_t* pairs, std::size_t n,
                              const ResultView& out, std::uint32_t* fallback);

/// The solids point_solid_pairs() measures a sphere's centre against.
enum class PointSolid { cylinder, cone, box };
/// Whether point_solid_pairs() answers pairs of these types: a sphere and a cylinder, cone or box, either order.
inline bool is_point_solid_pair(ShapeType a, ShapeType b) {
  const auto solid = [](ShapeType t) { return t == ShapeType::cylinder || t == ShapeType::cone || t == ShapeType::box; };
  return (a == ShapeType::sphere && solid(b)) || (b == ShapeType::sphere && solid(a));
}
/// The PointSolid of a solid's shape type (cylinder, cone or box).
inline PointSolid point_solid_of(ShapeType t) {
  return t == ShapeType::cone ? PointSolid::cone : t == ShapeType::box ? PointSolid::box : PointSolid::cylinder;
}

/// Sphere-cylinder, sphere-cone and sphere-box pairs (A is the sphere when `sphere_a`, the other side a `solid`;
/// `pairs` ascending), at every query level: the sphere's centre against the solid in closed form
/// (wide_point_solids.inl). Writes what segment_pairs writes; returns how many it left to the scalar
/// path (invalid input, a centre on the solid's boundary to rounding), their indices in fallback[0 .. count).
/// Which SIMD closed form answers pairs of types (a, b) under `options`, if any: the one rule the executor groups
/// pairs by, kernel_for() names and the tests exclude from their scalar comparisons. The kernels may still leave
/// single pairs to the per-pair path (invalid input, touching cores, inflated boxes).
enum class WideClosedForm { none, segments, boxes, point_solids };
inline WideClosedForm wide_closed_form(ShapeType a, ShapeType b, const QueryOptions& options) {
  if (!options.closed_forms) return WideClosedForm::none;
  const auto segment = [](ShapeType t) { return t == ShapeType::sphere || t == ShapeType::capsule; };
  if (segment(a) && segment(b)) return WideClosedForm::segments;
  // A sphere's centre against a cylinder or cone (a 2D distance in the solid's section) or a box
  // (wide_point_solids.inl).
  if (is_point_solid_pair(a, b)) return WideClosedForm::point_solids;
  // As setup_pair(): the separating-axis test is exact for boolean queries with a zero margin.
  if (a == ShapeType::box && b == ShapeType::box && options.level == QueryLevel::boolean && options.margin == 0.0)
    return WideClosedForm::boxes;
  return WideClosedForm::none;
}

std::size_t point_solid_pairs(InstructionSet isa, const PairView& in, bool sphere_a, PointSolid solid,
                              const std::uint32_t* pairs, std::size_t n, const ClosedFormQuery& query,
                              const ResultView& out, std::uint32_t* fallback);

}  // namespace batchcol::kernels::simd
