// Ray entry into a convex hull without visiting every face: Newton's method on the hull's gauge function, with the
// active face found by hill climbing on the polar (dual) polytope.
//
// With an interior point p and the facet planes <n_i, x> <= c_i (h_i = c_i - <n_i, p> > 0), x is in the hull iff
// g(x) = max_i <u_i, x - p> <= 1, u_i = n_i / h_i: g is the support function of the polar polytope conv{u_i}, so the
// face active at x (the argmax) is found by hill climbing over the polar's vertices, i.e. over facets that share an
// edge: on a convex polytope a vertex that no neighbour improves on maximises a linear function. Along the ray,
// g(o + t d) is convex and piecewise linear; from t = 0 (outside), Newton's step moves t to where the active face's
// plane is crossed, which never passes the entry (the plane lies below g) and reaches it after finitely many steps.
// The step is t = (c_f - <n_f, o>) / <n_f, d>, computed exactly as in the Cyrus-Beck kernel, so both give the same t
// for the same face. A miss: the active face does not face the ray (g no longer decreases) or t passes t_max.
// Coplanar triangles of one facet (qhull triangulates facets) are merged into one plane so the polar has no repeated
// vertices, on which hill climbing could stop early.
#pragma once

#include "batchcol/types.hpp"
#include "kernels/rays/ray_interval.hpp"
#include "kernels/shape_core.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

namespace batchcol::kernels::rays {

template <class T> struct HullWalk {
  std::vector<T> nx, ny, nz, c;  // one plane per facet
  std::vector<T> ux, uy, uz;     // polar vertices n / h
  std::vector<std::uint32_t> adjacency_begin, adjacency;  // facets sharing an edge (compressed rows)
  // Where climbs start: a cube map of directions (6 faces x kSeedGrid^2 cells) to the facet maximising the polar's
  // linear function at the cell's centre direction, so a climb from the origin's direction starts next to its end.
  static constexpr int kSeedGrid = 16;
  std::vector<std::uint32_t> seeds;
  Vec3<T> p = Vec3<T>::Zero();       // interior point (the vertex mean)
  std::size_t planes() const { return nx.size(); }
};

inline std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

template <class T> HullWalk<T> make_hull_walk(const HullView& hull) {
  const std::uint32_t F = hull.face_count;
  const auto normal = [&](std::uint32_t f) { return hull_face_normal(hull, f); };
  const auto offset = [&](std::uint32_t f) { return normal(f).dot(hull_vertex(hull, hull.faces[3 * f])); };
  // Triangles that share an edge and a plane (within 1e-12 of the hull's size) belong to one facet.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> edges;
  for (std::uint32_t f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = hull.faces[3 * f + k], b = hull.faces[3 * f + (k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  std::vector<std::uint32_t> parent(F);
  std::iota(parent.begin(), parent.end(), 0u);
  const double tol = 1e-12 * (1.0 + hull.radius);
  for (const auto& [edge, faces] : edges) {
    if (faces.size() != 2) continue;
    const std::uint32_t f = faces[0], g = faces[1];
    if ((normal(f) - normal(g)).norm() <= 1e-12 && std::abs(offset(f) - offset(g)) <= tol)
      parent[find_root(parent, f)] = find_root(parent, g);
  }
  std::vector<std::uint32_t> facet(F, UINT32_MAX);
  HullWalk<T> w;
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::uint32_t v = 0; v < hull.vertex_count; ++v) p += hull_vertex(hull, v);
  p /= double(hull.vertex_count);
  w.p = p.cast<T>();
  std::vector<std::uint32_t> representative;
  for (std::uint32_t f = 0; f < F; ++f) {
    const std::uint32_t r = find_root(parent, f);
    if (facet[r] == UINT32_MAX) facet[r] = static_cast<std::uint32_t>(representative.size()), representative.push_back(r);
    facet[f] = facet[r];
  }
  for (std::uint32_t r : representative) {
    const Eigen::Vector3d n = normal(r);
    const double c = offset(r), h = c - n.dot(p);
    w.nx.push_back(T(n.x())), w.ny.push_back(T(n.y())), w.nz.push_back(T(n.z())), w.c.push_back(T(c));
    w.ux.push_back(T(n.x() / h)), w.uy.push_back(T(n.y() / h)), w.uz.push_back(T(n.z() / h));
  }
  std::vector<std::vector<std::uint32_t>> neighbours(representative.size());
  for (const auto& [edge, faces] : edges)
    for (std::uint32_t a : faces)
      for (std::uint32_t b : faces)
        if (facet[a] != facet[b]) neighbours[facet[a]].push_back(facet[b]);
  w.adjacency_begin.push_back(0);
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
    w.adjacency.insert(w.adjacency.end(), n.begin(), n.end());
    w.adjacency_begin.push_back(static_cast<std::uint32_t>(w.adjacency.size()));
  }
  // Each cell's facet by hill climbing from the previous cell's (neighbouring directions have neighbouring facets),
  // exact for a linear function on the convex polar; a seed is only where a climb starts, so a tie broken either
  // way changes nothing but the climb's length.
  const int n = HullWalk<T>::kSeedGrid;
  std::uint32_t best = 0;
  for (int face = 0; face < 6; ++face)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        double dir[3];
        const int k = face / 2;
        dir[k] = face % 2 ? -1.0 : 1.0;
        dir[(k + 1) % 3] = -1.0 + (2.0 * a + 1.0) / n;
        dir[(k + 2) % 3] = -1.0 + (2.0 * b + 1.0) / n;
        const auto value = [&](std::uint32_t i) {
          return double(w.ux[i]) * dir[0] + double(w.uy[i]) * dir[1] + double(w.uz[i]) * dir[2];
        };
        double best_value = value(best);
        for (bool moved = true; moved;) {
          moved = false;
          const std::uint32_t from = best;
          for (std::uint32_t j = w.adjacency_begin[from]; j < w.adjacency_begin[from + 1]; ++j)
            if (const double v = value(w.adjacency[j]); v > best_value) best_value = v, best = w.adjacency[j], moved = true;
        }
        w.seeds.push_back(best);
      }
  return w;
}

/// A start for ray_hull_walk() from the entry `ball_enter` of the ray into the hull's bounding ball about the local
/// origin (radius `bound`, computed in T): moved back along the ray by 1024 ulps of (|o| + bound), far more than the
/// rounding of the entry and of o + t d (a few ulps of |o|), so the point is outside the hull even where the hull
/// touches its ball. Only a start: a shorter or longer walk, the same answer.
template <class T> T hull_walk_start(T ball_enter, const Vec3<T>& o, const Vec3<T>& d, T bound) {
  const T scale = std::max(std::abs(o.x()), std::max(std::abs(o.y()), std::abs(o.z()))) + bound;
  const T dmax = std::max(std::abs(d.x()), std::max(std::abs(d.y()), std::abs(d.z())));
  return ball_enter - T(1024) * machine_epsilon<T>() * scale / dmax;
}

/// The entry of the ray o + t d, t in [0, t_max], into the hull; `ok` false when the step budget ran out (the caller
/// then clips against every plane). `t_start` (>= 0) is a parameter known to lie outside the hull, or at most on its
/// entry: the walk starts there instead of at the origin. Callers pass the entry into the hull's bounding ball, which
/// they test first anyway: for a hull close to its ball (points on a sphere) the facet active there is already the
/// entry facet or next to it, so the climb from the cube-map seed is a move or two and one Newton step reaches the
/// entry, where starting at the far origin climbs and steps across the hull's side. The answer does not depend on
/// the start: t is computed from the entry facet's plane and o, d only (a point at t_start found inside the hull, by
/// rounding, restarts the walk from 0).
template <class T> LocalHit<T> ray_hull_walk(const HullWalk<T>& w, const Vec3<T>& o, const Vec3<T>& d, T t_max,
                                             bool& ok, T t_start = T(0)) {
  ok = true;
  LocalHit<T> h;
  const auto value = [&](std::uint32_t i, const Vec3<T>& q) { return (w.ux[i] * q.x() + w.uy[i] * q.y()) + w.uz[i] * q.z(); };
  if (!(t_start > T(0) && t_start <= t_max)) t_start = T(0);
  T t = t_start;
  Vec3<T> q = t > T(0) ? Vec3<T>((o + t * d) - w.p) : Vec3<T>(o - w.p);  // x - p
  // The cube-map cell of q's direction (the largest component picks the face).
  const T aq[3] = {std::abs(q.x()), std::abs(q.y()), std::abs(q.z())};
  const int k = aq[0] >= aq[1] ? (aq[0] >= aq[2] ? 0 : 2) : (aq[1] >= aq[2] ? 1 : 2);
  std::uint32_t f = w.seeds[0];
  if (aq[k] > T(0)) {
    const int n = HullWalk<T>::kSeedGrid;
    const T scale = T(0.5 * n) / aq[k];
    const auto cell = [&](T c) {  // c / |q_k| in [-1, 1] to [0, n)
      const T x = c * scale + T(0.5 * n);
      return x <= T(0) ? 0 : x >= T(n - 1) ? n - 1 : static_cast<int>(x);
    };
    const int face = 2 * k + (q[k] < T(0) ? 1 : 0);
    f = w.seeds[static_cast<std::size_t>((face * n + cell(q[(k + 1) % 3])) * n + cell(q[(k + 2) % 3]))];
  }
  T best = value(f, q);
  // Rounding of g near 1: a point within a few ulps of the active plane counts as on it.
  const T one = T(1) + T(16) * machine_epsilon<T>();
  const std::size_t budget = 4 * w.planes() + 64;
  std::size_t moves = 0;
  for (int step = 0; step < 64; ++step) {
    for (bool moved = true; moved;) {  // hill climbing to the active facet at q
      moved = false;
      const std::uint32_t from = f;
      for (std::uint32_t k = w.adjacency_begin[from]; k < w.adjacency_begin[from + 1]; ++k) {
        const std::uint32_t j = w.adjacency[k];
        const T v = value(j, q);
        if (v > best) best = v, f = j, moved = true;
      }
      if (++moves > budget) {
        ok = false;
        return h;
      }
    }
    if (best <= one) {  // on or inside the hull
      if (step == 0 && t > T(0)) return ray_hull_walk(w, o, d, t_max, ok);  // the start was not outside
      h.hit = true;
      h.t = t;
      h.normal = t > T(0) ? Vec3<T>(w.nx[f], w.ny[f], w.nz[f]) : Vec3<T>(-d / norm3(d));
      return h;
    }
    const T denom = (w.nx[f] * d.x() + w.ny[f] * d.y()) + w.nz[f] * d.z();
    if (!(denom < T(0))) return h;  // g does not decrease any more: the ray misses
    const T next = (w.c[f] - ((w.nx[f] * o.x() + w.ny[f] * o.y()) + w.nz[f] * o.z())) / denom;
    if (next > t_max) return h;
    if (!(next > t)) {  // no progress: q is on the active plane up to rounding
      if (step == 0 && t > T(0)) return ray_hull_walk(w, o, d, t_max, ok);
      h.hit = true;
      h.t = t;
      h.normal = t > T(0) ? Vec3<T>(w.nx[f], w.ny[f], w.nz[f]) : Vec3<T>(-d / norm3(d));
      return h;
    }
    t = next;
    q = (o + t * d) - w.p;
    best = value(f, q);
  }
  ok = false;
  return h;
}

}  // namespace batchcol::kernels::rays
