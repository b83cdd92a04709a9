// Plain types shared by every layer, in the spirit of Box2D's id.h: no Eigen, no shape model, no containers, so
// the low layers (broadphase/, later kernels/) can include this header and nothing else of the public API.
// The CMake targets of those layers see only this file, errors.hpp and export.hpp of batchcol/ (see
// broadphase/CMakeLists.txt): including anything else from engine/include or engine/src fails to compile there.
#pragma once

namespace batchcol {

/// An axis-aligned box as six plain doubles: what the broad phase stores and checks. The public batchcol::Aabb
/// (shapes.hpp, Eigen vectors) has the same min[k] / max[k] access, so code written against either compiles for
/// both (broadphase::AabbSoa::set is a template over the box type for that reason).
struct PlainAabb {
  double min[3] = {0, 0, 0};
  double max[3] = {0, 0, 0};
};

}  // namespace batchcol
