// Building and validating the float AABB arrays (see aabb_soa.hpp for why float and why outward rounding).
#include "broadphase/aabb_soa.hpp"

#include "batchcol/errors.hpp"
#include "broadphase/pairs.hpp"

#include <tbb/parallel_reduce.h>
#include <tbb/blocked_range.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace batchcol::broadphase {
namespace {

const char* const kAxis[3] = {"x", "y", "z"};

// Whether a box in [begin, end) has a non-finite coordinate or min > max: branch-free per box so that the loop
// vectorises (the exact index is searched only in a range that has one). A NaN fails every comparison; -inf fails
// lo >= -FLT_MAX, +inf fails hi <= FLT_MAX, and lo = +inf or hi = -inf either fails lo <= hi or makes the other
// coordinate infinite too.
bool any_bad_box(const AabbSoa& b, std::size_t begin, std::size_t end) {
  unsigned bad = 0;
  for (int a = 0; a < 3; ++a) {
    const float* lo = b.min(a);
    const float* hi = b.max(a);
    for (std::size_t i = begin; i < end; ++i)
      bad |= static_cast<unsigned>(!((lo[i] <= hi[i]) & (lo[i] >= -FLT_MAX) & (hi[i] <= FLT_MAX)));
  }
  return bad != 0;
}

// The double coordinate must round to a finite float: beyond FLT_MAX the cast would give inf (or be undefined).
void check_coordinate(std::size_t i, const char* which, int axis, double value) {
  if (!std::isfinite(value) || std::fabs(value) > static_cast<double>(FLT_MAX)) {
    std::ostringstream s;
    s << "broadphase: object " << i << ": " << which << "." << kAxis[axis] << " = " << value
      << (std::isfinite(value) ? " is outside the float range" : " is not finite (halfspaces and NaN poses have no "
                                                                  "finite box)");
    throw InputError(s.str());
  }
}

}  // namespace

float float_down(double x) {
  float f = static_cast<float>(x);  // round to nearest
  if (static_cast<double>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
  return f == 0.0f ? 0.0f : f;  // canonical +0: -0 and +0 must give the same sort key
}

float float_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f == 0.0f ? 0.0f : f;
}

void AabbSoa::resize(std::size_t n) {
  for (auto* v : {&min_x, &min_y, &min_z, &max_x, &max_y, &max_z}) v->resize(n, 0.0f);
}

void AabbSoa::set(std::size_t i, const PlainAabb& box, double margin) {
  if (!(margin >= 0.0) || !std::isfinite(margin)) {
    std::ostringstream s;
    s << "broadphase: object " << i << ": margin " << margin << " must be finite and >= 0";
    throw InputError(s.str());
  }
  float lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    check_coordinate(i, "min", a, box.min[a]);
    check_coordinate(i, "max", a, box.max[a]);
    if (!(box.min[a] <= box.max[a])) {
      std::ostringstream s;
      s << "broadphase: object " << i << ": min." << kAxis[a] << " = " << box.min[a] << " > max." << kAxis[a]
        << " = " << box.max[a];
      throw InputError(s.str());
    }
    const double l = box.min[a] - margin, h = box.max[a] + margin;
    check_coordinate(i, "min - margin", a, l);
    check_coordinate(i, "max + margin", a, h);
    lo[a] = float_down(l);
    hi[a] = float_up(h);
  }
  min_x[i] = lo[0], min_y[i] = lo[1], min_z[i] = lo[2];
  max_x[i] = hi[0], max_y[i] = hi[1], max_z[i] = hi[2];
}

void validate_aabbs(const AabbSoa& b) {
  const std::size_t n = b.size();
  for (const auto* v : {&b.min_y, &b.min_z, &b.max_x, &b.max_y, &b.max_z})
    if (v->size() != n) throw InputError("broadphase: the six AABB arrays must have the same size");
  if (n >= std::numeric_limits<std::uint32_t>::max())
    throw InputError("broadphase: at most 2^32 - 2 objects (pairs store 32-bit indices)");
  // Lowest bad index, found in parallel; min is associative and commutative, so the answer is deterministic.
  const std::size_t bad = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), n,
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t best) {
        if (r.begin() >= best || !any_bad_box(b, r.begin(), r.end())) return best;
        for (std::size_t i = r.begin(); i < r.end() && i < best; ++i)
          for (int a = 0; a < 3; ++a) {
            const float lo = b.min(a)[i], hi = b.max(a)[i];
            // !(lo <= hi) is also true when either is NaN; the finiteness test catches +-inf.
            if (!(lo <= hi) || !std::isfinite(lo) || !std::isfinite(hi)) return i;
          }
        return best;
      },
      [](std::size_t x, std::size_t y) { return std::min(x, y); });
  if (bad == n) return;
  std::ostringstream s;
  s << "broadphase: object " << bad << ": ";
  for (int a = 0; a < 3; ++a) {
    const float lo = b.min(a)[bad], hi = b.max(a)[bad];
    if (!std::isfinite(lo)) { s << "min." << kAxis[a] << " = " << lo << " is not finite"; break; }
    if (!std::isfinite(hi)) { s << "max." << kAxis[a] << " = " << hi << " is not finite"; break; }
    if (!(lo <= hi)) { s << "min." << kAxis[a] << " = " << lo << " > max." << kAxis[a] << " = " << hi; break; }
  }
  throw InputError(s.str());
}

void validate_filter(const FilterSoa& f, std::size_t objects) {
  if (f.group.size() != f.mask.size())
    throw InputError("broadphase: filter group and mask arrays must have the same size");
  if (f.has_groups() && f.group.size() != objects)
    throw InputError("broadphase: filter group/mask arrays must have one entry per object (" +
                     std::to_string(objects) + "), got " + std::to_string(f.group.size()));
  if (f.has_bodies() && f.body.size() != objects)
    throw InputError("broadphase: filter body array must have one entry per object (" + std::to_string(objects) +
                     "), got " + std::to_string(f.body.size()));
}

}  // namespace batchcol::broadphase
