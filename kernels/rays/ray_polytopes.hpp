// Exact ray intervals of the flat-faced shapes (local frame): box (slabs, Kay & Kajiya 1986), convex hull (the
// intersection of its face half-spaces: Cyrus-Beck clipping), triangle (Moeller-Trumbore 1997) and halfspace.
#pragma once

#include "batchcol/types.hpp"
#include "kernels/rays/ray_convex_planes.hpp"
#include "kernels/rays/ray_hull_walk.hpp"
#include "kernels/rays/ray_interval.hpp"

#include <cstddef>
#include <vector>

namespace batchcol::kernels::rays {

/// Box with half extents e.
template <class T> RayInterval<T> ray_box(const Vec3<T>& o, const Vec3<T>& d, const Vec3<T>& e) {
  RayInterval<T> in = slab(o.x(), d.x(), -e.x(), e.x(), Vec3<T>(T(1), T(0), T(0)));
  in = intersect(in, slab(o.y(), d.y(), -e.y(), e.y(), Vec3<T>(T(0), T(1), T(0))));
  return intersect(in, slab(o.z(), d.z(), -e.z(), e.z(), Vec3<T>(T(0), T(0), T(1))));
}

/// Halfspace {x : <n, x> <= c}, n unit.
template <class T> RayInterval<T> ray_halfspace(const Vec3<T>& o, const Vec3<T>& d, const Vec3<T>& n, T c) {
  const T denom = dot3(n, d), dist = c - dot3(n, o);  // t denom <= dist inside
  if (denom == T(0)) return dist >= T(0) ? RayInterval<T>::everything() : RayInterval<T>::nothing();
  const T t = dist / denom;
  if (denom < T(0)) return {t, infinity<T>(), n};
  return {-infinity<T>(), t, n};
}

/// Triangle (a 2-D solid): [t, t] where the ray crosses its interior or edges, empty when the line lies in its
/// plane (a set of measure zero that no tessellation reports either). The normal faces the ray.
template <class T> RayInterval<T> ray_triangle(const Vec3<T>& o, const Vec3<T>& d, const Vec3<T>& a, const Vec3<T>& b,
                                               const Vec3<T>& c) {
  const Vec3<T> e1 = b - a, e2 = c - a;
  const Vec3<T> p = cross3(d, e2);
  const T det = dot3(e1, p);
  if (det == T(0)) return RayInterval<T>::nothing();
  const T inv = T(1) / det;
  const Vec3<T> s = o - a;
  const T u = dot3(s, p) * inv;
  if (!(u >= T(0) && u <= T(1))) return RayInterval<T>::nothing();
  const Vec3<T> q = cross3(s, e1);
  const T v = dot3(d, q) * inv;
  if (!(v >= T(0) && u + v <= T(1))) return RayInterval<T>::nothing();
  const T t = dot3(e2, q) * inv;
  Vec3<T> n = cross3(e1, e2);
  n /= norm3(n);
  if (dot3(n, d) > T(0)) n = -n;
  return {t, t, n};
}

/// A hull's face planes <n_i, x> <= c_i in structure-of-arrays form, padded to a multiple of kHullPlaneBlock with
/// planes 0 <= 1 (always satisfied), so that the clipping loop runs on whole blocks the compiler vectorises.
constexpr std::size_t kHullPlaneBlock = 8;
template <class T> struct HullPlanes {
  std::vector<T> nx, ny, nz, c;
  std::size_t faces = 0;  // real planes (the rest is padding)
  HullWalk<T> walk;       // for hulls of kHullWalkMinFaces faces or more (ray_hull_walk.hpp)
};

/// Below this many faces the clipping loop over all planes is cheaper than the walk's climbs (a few blocks of 8).
constexpr std::size_t kHullWalkMinFaces = 48;

template <class T> HullPlanes<T> make_hull_planes(const HullView& hull) {
  HullPlanes<T> p;
  p.faces = hull.face_count;
  const std::size_t padded = (p.faces + kHullPlaneBlock - 1) / kHullPlaneBlock * kHullPlaneBlock;
  p.nx.assign(padded, T(0)), p.ny.assign(padded, T(0)), p.nz.assign(padded, T(0)), p.c.assign(padded, T(1));
  for (std::size_t i = 0; i < p.faces; ++i) {
    const Eigen::Vector3d n = hull_face_normal(hull, std::uint32_t(i));
    const Eigen::Vector3d v = hull_vertex(hull, hull.faces[3 * i]);
    p.nx[i] = T(n.x()), p.ny[i] = T(n.y()), p.nz[i] = T(n.z());
    p.c[i] = T(n.dot(v));
  }
  if (p.faces >= kHullWalkMinFaces) p.walk = make_hull_walk<T>(hull);
  return p;
}

/// Cyrus-Beck: enter = max over faces turned against d of dist_i / denom_i, exit = min over the others; a face
/// parallel to the ray empties the interval when the line is outside it (loop in ray_convex_planes.cpp; `isa` caps
/// its instruction set, see clip_planes()).
template <class T>
RayInterval<T> ray_convex(const Vec3<T>& o, const Vec3<T>& d, const HullPlanes<T>& planes, int isa = 2) {
  const T oa[3] = {o.x(), o.y(), o.z()}, da[3] = {d.x(), d.y(), d.z()};
  const PlaneClip<T> clip = clip_planes(planes.nx.data(), planes.ny.data(), planes.nz.data(), planes.c.data(),
                                        planes.nx.size(), oa, da, isa);
  if (clip.outside) return RayInterval<T>::nothing();
  RayInterval<T> in;
  in.enter = clip.enter, in.exit = clip.exit;
  if (!in.empty() && in.enter > -infinity<T>()) {
    in.normal = Vec3<T>(planes.nx[clip.face], planes.ny[clip.face], planes.nz[clip.face]);
  }
  return in;
}

}  // namespace batchcol::kernels::rays
