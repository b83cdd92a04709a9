// The shapes of a ShapeTable prepared for the ray kernels (cores, and face planes for hulls), in precision T.
#pragma once

#include "batchcol/shapes.hpp"
#include "kernels/rays/ray_shape.hpp"

#include <vector>

namespace batchcol::detail {

template <class T> struct PreparedRayShapes {
  std::vector<kernels::rays::HullPlanes<T>> planes;  // per shape (empty for non-hulls)
  std::vector<kernels::rays::RayShape<T>> shapes;

  PreparedRayShapes() = default;
  explicit PreparedRayShapes(const ShapeTable& table) { prepare(table); }
  PreparedRayShapes(const PreparedRayShapes&) = delete;  // shapes point into planes
  PreparedRayShapes& operator=(const PreparedRayShapes&) = delete;

  void prepare(const ShapeTable& table) {
    planes.assign(table.size(), {});
    shapes.clear();
    shapes.reserve(table.size());
    for (std::size_t s = 0; s < table.size(); ++s) {
      const Shape& shape = table[s];
      if (shape.type == ShapeType::convex) planes[s] = kernels::rays::make_hull_planes<T>(*shape.hull);
      shapes.push_back(kernels::rays::make_ray_shape<T>(shape, &planes[s]));
    }
  }
};

}  // namespace batchcol::detail
