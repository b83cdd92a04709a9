// World AABBs from support functions: the extent of a convex shape along a world axis e is <support(R^T e), e>,
// so six support queries give the tight box of any shape type.
#include "batchcol/shapes.hpp"
#include "kernels/support.hpp"
#include "shape_table_access.hpp"

#include <limits>

namespace batchcol {

Aabb compute_aabb(const Shape& shape, const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation) {
  if (shape.type == ShapeType::halfspace) {
    const double inf = std::numeric_limits<double>::infinity();
    return {Eigen::Vector3d::Constant(-inf), Eigen::Vector3d::Constant(inf)};
  }
  const OwnedShapeView view(shape);
  const kernels::ShapeCore<double> core = kernels::make_core<double>(view.view);
  const Eigen::Matrix3d R = rotation.normalized().toRotationMatrix();
  kernels::SupportHint hint;
  Aabb box;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d e = R.row(axis).transpose();  // world axis in the local frame
    box.max[axis] = translation[axis] + e.dot(kernels::support(core, e, hint)) + core.radius;
    box.min[axis] = translation[axis] + e.dot(kernels::support(core, Eigen::Vector3d(-e), hint)) - core.radius;
  }
  return box;
}

}  // namespace batchcol
