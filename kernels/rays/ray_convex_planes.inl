// The body of the plane clipping loop (see ray_convex_planes.cpp), included once per instruction set inside a
// `#pragma GCC target` region and a namespace of its own, so that every function here is compiled for that set
// (GCC lowers vector code of an inlined helper for the helper's own target, not the caller's).
// Expects T (double or float), V (8 lanes of T) and M (the matching 8-lane integer mask) to be defined.

namespace {

inline V splat(T x) {
  V v;
  for (std::size_t j = 0; j < 8; ++j) v[j] = x;
  return v;
}

inline M splat_mask(long long x) {
  M v;
  for (std::size_t j = 0; j < 8; ++j) v[j] = x;
  return v;
}

inline V load(const T* p) {
  V v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}

// a where the mask is set, else b, by bit operations.
inline V select(M mask, V a, V b) { return (V)(((M)a & mask) | ((M)b & ~mask)); }
inline M select_mask(M mask, M a, M b) { return (a & mask) | (b & ~mask); }

}  // namespace

PlaneClip<T> clip(const T* nx, const T* ny, const T* nz, const T* c, std::size_t n, const T* o, const T* d) {
  const V ox = splat(o[0]), oy = splat(o[1]), oz = splat(o[2]);
  const V dx = splat(d[0]), dy = splat(d[1]), dz = splat(d[2]);
  const V zero = splat(T(0));
  V en = splat(T(1)), ed = splat(T(-0.0)), xn = splat(T(1)), xd = splat(T(0));
  M face = splat_mask(0), outside = splat_mask(0), index;
  for (std::size_t j = 0; j < 8; ++j) index[j] = static_cast<long long>(j);
  const M step = splat_mask(8);
  for (std::size_t b = 0; b < n; b += 8) {
    const V ax = load(nx + b), ay = load(ny + b), az = load(nz + b), cc = load(c + b);
    const V denom = (ax * dx + ay * dy) + az * dz;
    const V dist = cc - ((ax * ox + ay * oy) + az * oz);
    const M entering = (M)(denom < zero) & (M)(dist * ed > en * denom);
    en = select(entering, dist, en);
    ed = select(entering, denom, ed);
    face = select_mask(entering, index, face);
    const M leaving = (M)(denom > zero) & (M)(dist * xd < xn * denom);
    xn = select(leaving, dist, xn);
    xd = select(leaving, denom, xd);
    outside |= (M)(denom == zero) & (M)(dist < zero);
    index += step;
  }
  PlaneClip<T> r{-std::numeric_limits<T>::infinity(), std::numeric_limits<T>::infinity(), 0u, false};
  for (std::size_t j = 0; j < 8; ++j) {
    const T enter = en[j] / ed[j], exit = xn[j] / xd[j];  // 1 / -0 = -inf and 1 / +0 = +inf for unused lanes
    const unsigned f = static_cast<unsigned>(face[j]);
    // Ties go to the lower face index, whatever lane found it.
    if (enter > r.enter || (enter == r.enter && f < r.face)) r.enter = enter, r.face = f;
    if (exit < r.exit) r.exit = exit;
    r.outside = r.outside || outside[j] != 0;
  }
  return r;
}
