// The shapes of a ShapeTable prepared for the ray kernels (cores, and face planes for hulls), in precision T.
#pragma once

#include "batchcol/shapes.hpp"
#include "kernels/rays/ray_shape.hpp"
#include "shape_table_access.hpp"

#include <vector>

namespace batchcol::detail {

template <class T> struct PreparedRayShapes {
  std::vector<kernels::rays::HullPlanes<T>> planes;  // per shape (empty for non-hulls)
  std::vector<HullView> hulls;                       // per shape (zeros for non-hulls): the cores point here
  std::vector<kernels::rays::RayShape<T>> shapes;

  PreparedRayShapes() = default;
  explicit PreparedRayShapes(const ShapeTable& table) { prepare(table); }
  PreparedRayShapes(const PreparedRayShapes&) = delete;  // shapes point into planes and hulls
  PreparedRayShapes& operator=(const PreparedRayShapes&) = delete;

  void prepare(const ShapeTable& table) {
    planes.assign(table.size(), {});
    hulls = ShapeTableAccess::hulls(table);
    shapes.clear();
    shapes.reserve(table.size());
    for (std::size_t s = 0; s < table.size(); ++s) {
      const ShapeView shape = shape_view(table[s], &hulls[s], ShapeTableAccess::bounding_radii(table)[s]);
      if (shape.type == ShapeType::convex) planes[s] = kernels::rays::make_hull_planes<T>(hulls[s]);
      shapes.push_back(kernels::rays::make_ray_shape<T>(shape, &planes[s]));
    }
  }
};

}  // namespace batchcol::detail
