// WideGjk's gate in front of the closed-form start candidates computed by the lanes' own start() (runs without
// WideGjkPairs' slot set-up: the penetration level, warm starts, the smoothing samples). Included inside WideGjk<T>
// (kernels/simd/wide_gjk.inl); tests/support/reference_start_gate.hpp is its scalar transcription.
//
// Every candidate (rim_candidate(), box_round_candidate(), box_ellipsoid_candidate(),
// round_ellipsoid_candidate()) is kept only where its direction n separates the cores (round_apart() and its
// twins). Where the cores overlap no direction does: for a point p of both A and B, max over A of <x, n> >= <p, n>
// >= min over B of <y, n>. So a lane whose cores are proved to overlap cannot take the candidate, and when no
// fresh lane can, start() need not compute it. The proof here costs no support call: the first support point's
// two points, sa (A's point furthest towards B's centre) and sb (B's point furthest towards A's), each tested
// inside the other core. Overlap-regime penetration pairs computed the candidates for nothing before this gate
// (box-cylinder +5.1%, box-cone +7.7% instructions per pair, bench/results/history/narrowphase-sessions.md).

/// A point counts as inside a core only inside the core shrunk by this factor (each half extent, radius,
/// half-height; an ellipsoid's quadratic form below kGateShrink). The margin makes the proof robust to the
/// separation tests' rounding: a point inside by a margin m gives every direction n a core gap <= -m |n|, far
/// below the tests' rounding error (a few ulps of |t| |n|) for cores not flatter than ~1e-9 of their distance.
static constexpr T kGateShrink = T(1) - T(1e-6);

/// Whether q (the core's frame) lies inside core s shrunk by kGateShrink; never for a capsule's segment or a
/// sphere's point (no interior) or other cores (no candidate pairs). A cone: apex (0, 0, h), base rim of radius r
/// at z = -h; shrunk, its radius at height z is k r (k h - z) / (2 h).
AI static mask core_contains(const Side& s, const V3& q) {
  const real zero = splat(T(0)), k = splat(kGateShrink);
  const auto abs = [&](const real& v) { return select(v < zero, -v, v); };
  switch (s.type) {
    case ShapeType::box: return ((abs(q.x) < k * s.s0) & (abs(q.y) < k * s.s1)) & (abs(q.z) < k * s.s2);
    case ShapeType::cylinder: {
      const real r = k * s.s0;
      return (abs(q.z) < k * s.s1) & (q.x * q.x + q.y * q.y < r * r);
    }
    case ShapeType::cone: {
      const real h = k * s.s1, e = (k * s.s0) * (h - q.z), h2 = s.s1 + s.s1;
      return ((q.z > -h) & (e > zero)) & ((h2 * h2) * (q.x * q.x + q.y * q.y) < e * e);
    }
    case ShapeType::ellipsoid: {  // (x / a)^2 + (y / b)^2 + (z / c)^2 < k, times (a b c)^2: no division
      const real u = q.x * (s.s1 * s.s2), v = q.y * (s.s0 * s.s2), w = q.z * (s.s0 * s.s1);
      const real p = (s.s0 * s.s1) * s.s2;
      return (u * u + v * v) + w * w < (k * p) * p;
    }
    default: return splat_mask(0);
  }
}

/// The lanes whose cores certainly overlap: sa (A's frame) inside B, mapped into B's frame by R^T (sa - t), or sb
/// (A's frame) inside A. Either is a point of both cores.
AI static mask cores_overlap(const Lanes& L, const V3& sa, const V3& sb) {
  const real* R = L.R;
  const V3 v = {sa.x - L.t[0], sa.y - L.t[1], sa.z - L.t[2]};
  const V3 q = {(R[0] * v.x + R[3] * v.y) + R[6] * v.z, (R[1] * v.x + R[4] * v.y) + R[7] * v.z,
                (R[2] * v.x + R[5] * v.y) + R[8] * v.z};
  return core_contains(L.B, q) | core_contains(L.A, sb);
}
