// One ray against one shape in its local frame: picks the exact kernel of the shape type, or the GJK ray cast for
// inflated shapes that have none. Exact: sphere and capsule (their radius includes the inflation), halfspace (the
// inflation moves its plane), and every other type without inflation. Inflated box, cylinder, cone, ellipsoid, hull
// and triangle go through ray_gjk (certified: the hit point is outside the shape and within the tolerance of it).
#pragma once

#include "kernels/rays/ray_gjk.hpp"
#include "kernels/rays/ray_polytopes.hpp"
#include "kernels/rays/ray_quadrics.hpp"
#include "kernels/shape_core.hpp"

namespace batchcol::kernels::rays {

/// A shape prepared for rays: its core, inflation, bounding radius and (hulls) face planes owned by the caller.
template <class T> struct RayShape {
  ShapeCore<T> core;
  T inflation = T(0);
  T bound = T(0);                         // bounding radius about the local origin (inflation included)
  const HullPlanes<T>* planes = nullptr;  // convex only
};

/// `shape`'s hull view (convex) must outlive the RayShape: its core points to it.
template <class T> RayShape<T> make_ray_shape(const ShapeView& shape, const HullPlanes<T>* planes) {
  RayShape<T> r;
  r.core = make_core<T>(shape);
  r.inflation = T(shape.inflation);
  r.bound = shape.type == ShapeType::halfspace ? T(0) : T(shape.bounding_radius);
  r.planes = planes;
  return r;
}

/// True when the shape's rays go through the GJK ray cast (tolerance-certified) instead of an exact kernel.
inline bool uses_ray_gjk(const ShapeView& shape) {
  return shape.inflation > 0.0 && shape.type != ShapeType::sphere && shape.type != ShapeType::capsule &&
         shape.type != ShapeType::halfspace;
}

/// An uninflated hull whose ray is known to meet its bounding ball (radius at least `bound`) from `ball_entry` on:
/// the walk from there, or every plane clipped when the walk gives up. ray_local()'s convex case, callable on its own
/// so that a caller that already knows the shape type (the scene's leaf visits) skips the dispatch (~18 instructions
/// a call); always inlined, since as a call its frame and the copy of the result cost ~45 more (callgrind, 10k hulls).
/// `isa` caps the clipping loop's instruction set (clip_planes()).
template <class T>
[[gnu::always_inline]] inline LocalHit<T> ray_local_hull(const RayShape<T>& s, const Vec3<T>& o, const Vec3<T>& d,
                                                         T t_max, T ball_entry, int isa = 2) {
  if (s.planes->walk.planes() > 0) {
    bool ok = false;
    const LocalHit<T> h = ray_hull_walk(s.planes->walk, o, d, t_max, ok, ball_entry);
    if (ok) return h;
  }
  return finish(ray_convex(o, d, *s.planes, isa), d, t_max);
}

/// `ball_entry`: when the caller has already found that the segment [0, t_max] meets a ball about the local origin of
/// radius at least `bound` (the scene's world-frame filter), the parameter where the ray enters that ball; hulls
/// then skip their own ball test and start the walk there. NaN (the default): not known. `isa`: as ray_local_hull().
template <class T> LocalHit<T> ray_local(const RayShape<T>& s, const Vec3<T>& o, const Vec3<T>& d, T t_max,
                                         const RayGjkSettings& settings, T ball_entry = quiet_nan<T>(), int isa = 2) {
  const ShapeCore<T>& c = s.core;
  if (c.type == ShapeType::halfspace) {
    return finish(ray_halfspace(o, d, c.halfspace_normal, c.halfspace_offset + s.inflation), d, t_max);
  }
  if (s.inflation > T(0) && c.type != ShapeType::sphere && c.type != ShapeType::capsule) {
    return ray_gjk(c, s.inflation, s.bound, o, d, t_max, settings);
  }
  switch (c.type) {
    case ShapeType::sphere: return finish(ray_sphere(o, d, c.radius), d, t_max);
    case ShapeType::capsule: return finish(ray_capsule(o, d, c.radius, c.size.y()), d, t_max);
    case ShapeType::box: return finish(ray_box(o, d, c.size), d, t_max);
    case ShapeType::cylinder: return finish(ray_cylinder(o, d, c.size.x(), c.size.y()), d, t_max);
    case ShapeType::cone: return finish(ray_cone(o, d, c.size.x(), c.size.y()), d, t_max);
    case ShapeType::ellipsoid: return finish(ray_ellipsoid(o, d, c.size), d, t_max);
    case ShapeType::convex: {
      // The bounding ball first: most rays that reach a hull's box in a scene miss the hull, and the ball rejects
      // them for the cost of one sphere test instead of a pass over every face; the walk starts at the ball's entry.
      if (!(ball_entry == ball_entry)) {
        const RayInterval<T> ball = ray_sphere(o, d, s.bound * (T(1) + T(64) * machine_epsilon<T>()));
        if (ball.empty() || ball.exit < T(0) || ball.enter > t_max) return {};
        ball_entry = hull_walk_start(ball.enter, o, d, s.bound);
      }
      return ray_local_hull(s, o, d, t_max, ball_entry, isa);
    }
    case ShapeType::triangle:
      return finish(ray_triangle(o, d, c.triangle[0], c.triangle[1], c.triangle[2]), d, t_max);
    case ShapeType::halfspace: break;
  }
  return {};
}

}  // namespace batchcol::kernels::rays
