// The search structures of a convex hull (adjacency, neighbour blocks, direction table) for a hull the caller
// built: Shape::convex accepts only hulls whose structures the kernels can trust.
#pragma once

#include "batchcol/shapes.hpp"

#include <memory>

namespace batchcol {

/// `hull` itself when its adjacency, neighbour blocks and start table are present and consistent with its faces
/// and vertices; else a copy with them built. Throws InputError (naming the field) for a face index out of range
/// or an adjacency that contradicts the faces.
std::shared_ptr<const ConvexHull> with_search_structures(std::shared_ptr<const ConvexHull> hull);

}  // namespace batchcol
