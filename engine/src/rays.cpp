// Ray batches, names, option validation, and the per-ray input checks shared by the shape and scene forms.
#include "rays_common.hpp"

#include <cmath>
#include <string>

namespace batchcol {

void RayBatch::reserve(std::size_t n) {
  origin.reserve(n);
  direction.reserve(n);
  t_max.reserve(n);
}

std::size_t RayBatch::add(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double t) {
  origin.push_back(o);
  direction.push_back(d);
  t_max.push_back(t);
  return t_max.size() - 1;
}

std::size_t ShapeRayBatch::add(std::uint32_t shape_index, const Pose& pose, const Eigen::Vector3d& o,
                               const Eigen::Vector3d& d, double t) {
  shape.push_back(shape_index);
  translation.push_back(pose.translation);
  rotation.push_back(pose.rotation);
  return rays.add(o, d, t);
}

namespace {
constexpr const char* kRayQueryNames[] = {"closest", "any", "all"};
constexpr const char* kRayStatusNames[] = {"ok", "max_iterations", "invalid_input"};
}  // namespace

const char* to_string(RayQuery query) {
  const auto i = static_cast<std::size_t>(query);
  return i < 3 ? kRayQueryNames[i] : "unknown";
}

const char* to_string(RayStatus status) {
  const auto i = static_cast<std::size_t>(status);
  return i < 3 ? kRayStatusNames[i] : "unknown";
}

RayQuery parse_ray_query(const std::string& name) {
  for (std::size_t i = 0; i < 3; ++i)
    if (name == kRayQueryNames[i]) return static_cast<RayQuery>(i);
  throw InputError("unknown ray query '" + name + "' (valid: closest, any, all)");
}

void validate(const RayOptions& o) {
  if (!(std::isfinite(o.tolerance) && o.tolerance > 0.0))
    throw InputError("RayOptions.tolerance must be finite and > 0 (got " + std::to_string(o.tolerance) + ")");
  if (o.max_iterations < 1)
    throw InputError("RayOptions.max_iterations must be >= 1 (got " + std::to_string(o.max_iterations) + ")");
  if (o.threads < 0) throw InputError("RayOptions.threads must be >= 0 (got " + std::to_string(o.threads) + ")");
  if (o.precision != Precision::float64 && o.precision != Precision::float32)
    throw InputError("RayOptions.precision is not a Precision value");
  if (o.query != RayQuery::closest && o.query != RayQuery::any && o.query != RayQuery::all)
    throw InputError("RayOptions.query is not a RayQuery value");
}

namespace detail {

void check_ray_batch(const RayBatch& rays) {
  const std::size_t n = rays.t_max.size();
  for (const std::vector<double>* a : {&rays.origin.x, &rays.origin.y, &rays.origin.z, &rays.direction.x,
                                       &rays.direction.y, &rays.direction.z}) {
    if (a->size() != n)
      throw InputError("RayBatch: origin, direction and t_max must have the same size (t_max has " +
                       std::to_string(n) + ", another array " + std::to_string(a->size()) + ")");
  }
}

int ray_isa_index(InstructionSet requested) {
  switch (resolve_instruction_set(requested)) {
    case InstructionSet::avx512: return 2;
    case InstructionSet::avx2: return 1;
    default: return 0;
  }
}

bool ray_is_valid(const RayBatch& rays, std::size_t i) {
  const double ox = rays.origin.x[i], oy = rays.origin.y[i], oz = rays.origin.z[i];
  const double dx = rays.direction.x[i], dy = rays.direction.y[i], dz = rays.direction.z[i];
  const double t = rays.t_max[i];
  const bool finite = std::isfinite(ox) && std::isfinite(oy) && std::isfinite(oz) && std::isfinite(dx) &&
                      std::isfinite(dy) && std::isfinite(dz);
  // |d|^2 must not underflow to 0 either: the kernels divide by it.
  return finite && (dx * dx + dy * dy + dz * dz) > 0.0 && t >= 0.0;  // NaN t_max fails t >= 0
}

void size_ray_results(RayResults& r, std::size_t n, bool with_objects) {
  r.status.assign(n, RayStatus::invalid_input);
  r.hit.assign(n, 0);
  r.t.assign(n, std::nan(""));
  r.normal.x.assign(n, std::nan("")), r.normal.y.assign(n, std::nan("")), r.normal.z.assign(n, std::nan(""));
  r.object.assign(with_objects ? n : 0, ObjectHandle{});
  r.hit_begin.clear();
  r.all_t.clear();
  r.all_normal.resize(0);
  r.all_object.clear();
}

}  // namespace detail
}  // namespace batchcol
