#include "validate.hpp"

#include "results_fill.hpp"
#include "shape_table_access.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace batchcol {
namespace detail {

namespace {
constexpr std::size_t kRagged = static_cast<std::size_t>(-1);  // component arrays of different lengths
std::size_t length(const Vec3Array& v) {
  return v.y.size() == v.x.size() && v.z.size() == v.x.size() ? v.x.size() : kRagged;
}
std::size_t length(const QuatArray& q) {
  return q.x.size() == q.w.size() && q.y.size() == q.w.size() && q.z.size() == q.w.size() ? q.w.size() : kRagged;
}
}  // namespace

void validate_batch_layout(const PairBatch& b) {
  const std::size_t n = b.shape_a.size();
  const auto check = [n](std::size_t size, const char* name) {
    if (size == n) return;
    throw InputError(std::string("PairBatch::") + name + (size == kRagged ? " has component arrays of different "
                     "lengths" : " has " + std::to_string(size) + " entries, expected " + std::to_string(n)));
  };
  check(b.shape_b.size(), "shape_b");
  check(length(b.translation_a), "translation_a");
  check(length(b.translation_b), "translation_b");
  check(length(b.rotation_a), "rotation_a");
  check(length(b.rotation_b), "rotation_b");
  if (!b.warm_start.empty()) check(length(b.warm_start), "warm_start");
}

void validate_batch_layout(const PairBatchView& b) {
  const std::size_t n = b.size();
  // The message is built only on failure: built eagerly for the 16 arrays it was ~8k instructions a call (half of a
  // 16-pair call's cost, callgrind).
  const auto check = [n](const auto& span, const char* name, const char* component) {
    if (span.size() == n && (n == 0 || span.data() != nullptr)) return;
    const std::string what = std::string("PairBatchView::") + name + component;
    if (span.size() != n)
      throw InputError(what + " has " + std::to_string(span.size()) + " entries, expected " + std::to_string(n));
    throw InputError(what + " has " + std::to_string(n) + " entries but no data");
  };
  check(b.shape_a, "shape_a", "");
  check(b.shape_b, "shape_b", "");
  const auto vec3 = [&](const Vec3View& v, const char* name) {
    check(v.x, name, ".x"), check(v.y, name, ".y"), check(v.z, name, ".z");
  };
  const auto quat = [&](const QuatView& q, const char* name) {
    check(q.w, name, ".w"), check(q.x, name, ".x"), check(q.y, name, ".y"), check(q.z, name, ".z");
  };
  vec3(b.translation_a, "translation_a");
  vec3(b.translation_b, "translation_b");
  quat(b.rotation_a, "rotation_a");
  quat(b.rotation_b, "rotation_b");
  if (!b.warm_start.empty()) vec3(b.warm_start, "warm_start");
}

void validate_shapes_for(const ShapeTable& shapes, const QueryOptions& options) {
  if (options.precision != Precision::float32 || shapes.size() == 0) return;
  const double smallest = ShapeTableAccess::smallest_size(shapes);
  const double largest = ShapeTableAccess::largest_radius(shapes);
  if (smallest >= kMinLengthFloat && largest <= kMaxLengthFloat) return;
  char text[200];
  std::snprintf(text, sizeof text,
                "precision float32 answers shapes of sizes %g to %g m only (the table holds sizes down to %g m and "
                "bounding radii up to %g m): use precision double",
                kMinLengthFloat, kMaxLengthFloat, smallest, largest);
  throw InputError(text);
}

void refuse_beyond_float_limits(const PairBatchView& batch, std::size_t begin, std::size_t end, PairResults& results) {
  const double *ax = batch.translation_a.x.data(), *ay = batch.translation_a.y.data();
  const double *az = batch.translation_a.z.data(), *bx = batch.translation_b.x.data();
  const double *by = batch.translation_b.y.data(), *bz = batch.translation_b.z.data();
  const auto beyond = [&](std::size_t i) {  // NaN is beyond too
    return !((std::abs(bx[i] - ax[i]) + std::abs(by[i] - ay[i])) + std::abs(bz[i] - az[i]) <= kMaxLengthFloat);
  };
  // Almost no batch has such a pair: a branch-free pass two pairs per SSE2 register (GCC's vector extension; the
  // plain loop did not vectorise) decides whether the per-pair pass runs at all. The per-pair test with its rare
  // store cost ~26 instructions a pair, 2-3% of a float boolean query (callgrind, AVX2 kernels).
  using V2 = double __attribute__((vector_size(16)));
  using M2 = long long __attribute__((vector_size(16)));
  const auto ld = [](const double* p) { V2 v; std::memcpy(&v, p, sizeof v); return v; };
  const auto abs2 = [](V2 v) { return V2(M2(v) & M2{~(1LL << 63), ~(1LL << 63)}); };
  M2 any2 = {0, 0};
  std::size_t i = begin;
  for (; i + 2 <= end; i += 2) {
    const V2 s = (abs2(ld(bx + i) - ld(ax + i)) + abs2(ld(by + i) - ld(ay + i))) + abs2(ld(bz + i) - ld(az + i));
    any2 |= ~(s <= V2{kMaxLengthFloat, kMaxLengthFloat});
  }
  bool any = (any2[0] | any2[1]) != 0;
  for (; i < end; ++i) any |= beyond(i);
  if (!any) return;
  for (i = begin; i < end; ++i)
    if (beyond(i)) fill_pair_defaults(results, i);
}

std::optional<Eigen::Quaterniond> unit_quaternion(const Eigen::Quaterniond& q) {
  double c[4] = {q.w(), q.x(), q.y(), q.z()};
  if (!normalize_unit_quaternion(c)) return std::nullopt;
  return Eigen::Quaterniond(c[0], c[1], c[2], c[3]);
}

}  // namespace detail

void validate(const QueryOptions& o) {
  const auto fail = [](const std::string& what) { throw InputError("QueryOptions::" + what); };
  if (!std::isfinite(o.tolerance) || o.tolerance < 0.0) fail("tolerance must be a finite number >= 0");
  if (!std::isfinite(o.relative_tolerance) || o.relative_tolerance < 0.0)
    fail("relative_tolerance must be a finite number >= 0");
  if (!std::isfinite(o.margin) || o.margin < 0.0) fail("margin must be a finite number >= 0");
  if (o.max_iterations < 1) fail("max_iterations must be >= 1");
  if (o.epa_max_iterations < 1) fail("epa_max_iterations must be >= 1");
  if (o.threads < 0 || o.threads > kMaxThreads) {
    fail("threads must be between 0 (all cores) and " + std::to_string(kMaxThreads) + ", got " +
         std::to_string(o.threads));
  }
  if (static_cast<int>(o.level) > static_cast<int>(QueryLevel::penetration)) fail("level is not a QueryLevel");
  if (static_cast<int>(o.solver) > static_cast<int>(Solver::automatic)) fail("solver is not a Solver");
  if (static_cast<int>(o.precision) > static_cast<int>(Precision::float32)) fail("precision is not a Precision");
  if (static_cast<int>(o.isa) > static_cast<int>(InstructionSet::avx512)) fail("isa is not an InstructionSet");
}

}  // namespace batchcol
