#include "peers/embree_rays.hpp"

#include <batchcol/errors.hpp>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace batchcol::peers {

bool have_embree() { return true; }

double tessellation_error(ShapeType type, double radius, const Tessellation& t) {
  const double chord = radius * (1.0 - std::cos(M_PI / t.segments));
  switch (type) {
    case ShapeType::cylinder:
    case ShapeType::cone: return chord;
    case ShapeType::ellipsoid: return 2.0 * chord;
    default: return 0.0;  // exact (triangles, Embree primitives)
  }
}

struct EmbreeRayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<std::uint32_t> prim_object[3];  // per geometry id (0 triangles, 1 spheres, 2 curves): object of prim
  std::size_t triangles = 0;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

using V = Eigen::Vector3d;

struct Mesh {
  std::vector<float> vertices;  // x, y, z
  std::vector<std::uint32_t> indices;
  std::vector<std::uint32_t> object;  // per triangle

  std::uint32_t vertex(const Pose& p, const V& local) {
    const V w = p.rotation * local + p.translation;
    vertices.push_back(float(w.x())), vertices.push_back(float(w.y())), vertices.push_back(float(w.z()));
    return static_cast<std::uint32_t>(vertices.size() / 3 - 1);
  }
  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t obj) {
    indices.push_back(a), indices.push_back(b), indices.push_back(c), object.push_back(obj);
  }
};

// Surface of revolution about z through the rings (rho_k, z_k), closed by the caps (rho = 0 rings are points).
void revolve(Mesh& m, const Pose& p, const std::vector<std::pair<double, double>>& rings, int segments,
             std::uint32_t obj) {
  std::vector<std::vector<std::uint32_t>> ids;
  for (const auto& [rho, z] : rings) {
    std::vector<std::uint32_t> ring;
    for (int s = 0; s < segments; ++s) {
      const double a = 2.0 * M_PI * s / segments;
      ring.push_back(m.vertex(p, V(rho * std::cos(a), rho * std::sin(a), z)));
    }
    ids.push_back(ring);
  }
  for (std::size_t k = 0; k + 1 < ids.size(); ++k)
    for (int s = 0; s < segments; ++s) {
      const int t = (s + 1) % segments;
      m.triangle(ids[k][s], ids[k + 1][s], ids[k + 1][t], obj);
      m.triangle(ids[k][s], ids[k + 1][t], ids[k][t], obj);
    }
  // Caps: fans over the first and last rings.
  for (std::size_t k : {std::size_t(0), ids.size() - 1}) {
    for (int s = 1; s + 1 < segments; ++s) m.triangle(ids[k][0], ids[k][s], ids[k][s + 1], obj);
  }
}

void add_box(Mesh& m, const Pose& p, const V& h, std::uint32_t obj) {
  std::uint32_t v[8];
  for (int i = 0; i < 8; ++i) v[i] = m.vertex(p, V(i & 1 ? h.x() : -h.x(), i & 2 ? h.y() : -h.y(), i & 4 ? h.z() : -h.z()));
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) m.triangle(v[f[0]], v[f[1]], v[f[2]], obj), m.triangle(v[f[0]], v[f[2]], v[f[3]], obj);
}

double ms_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

EmbreeRayScene::EmbreeRayScene(int threads) : impl_(std::make_unique<Impl>()) {
  const std::string config = threads > 0 ? "threads=" + std::to_string(threads) : "";
  impl_->device = rtcNewDevice(config.c_str());
  if (!impl_->device) throw InputError("Embree: rtcNewDevice failed");
}

EmbreeRayScene::~EmbreeRayScene() = default;

std::size_t EmbreeRayScene::triangle_count() const { return impl_->triangles; }

EmbreeRayScene::BuildTimes EmbreeRayScene::build(const std::vector<EmbreeObject>& objects, const Tessellation& tess) {
  const auto start = std::chrono::steady_clock::now();
  Impl& s = *impl_;
  if (s.scene) rtcReleaseScene(s.scene);
  s.scene = rtcNewScene(s.device);
  Mesh mesh;
  std::vector<float> spheres, curves;  // x, y, z, r
  for (auto& v : s.prim_object) v.clear();
  const int segs = tess.segments;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const Shape& sh = *objects[i].shape;
    const Pose& p = objects[i].pose;
    const auto obj = static_cast<std::uint32_t>(i);
    if (sh.inflation != 0.0 || sh.type == ShapeType::halfspace)
      throw InputError(std::string("Embree reference: ") + (sh.inflation != 0.0 ? "inflated shapes" : "halfspaces") +
                       " are not supported (object " + std::to_string(i) + ")");
    switch (sh.type) {
      case ShapeType::convex: {
        const std::uint32_t base = static_cast<std::uint32_t>(mesh.vertices.size() / 3);
        for (const V& v : sh.hull->vertices) mesh.vertex(p, v);
        for (const auto& f : sh.hull->faces) mesh.triangle(base + f[0], base + f[1], base + f[2], obj);
        break;
      }
      case ShapeType::box: add_box(mesh, p, sh.size, obj); break;
      case ShapeType::triangle: {
        const std::uint32_t a = mesh.vertex(p, sh.triangle[0]), b = mesh.vertex(p, sh.triangle[1]),
                            c = mesh.vertex(p, sh.triangle[2]);
        mesh.triangle(a, b, c, obj);
        break;
      }
      case ShapeType::sphere:
        spheres.insert(spheres.end(), {float(p.translation.x()), float(p.translation.y()), float(p.translation.z()),
                                       float(sh.size.x())});
        s.prim_object[1].push_back(obj);
        break;
      case ShapeType::capsule: {
        for (double z : {-sh.size.y(), sh.size.y()}) {
          const V w = p.rotation * V(0, 0, z) + p.translation;
          curves.insert(curves.end(), {float(w.x()), float(w.y()), float(w.z()), float(sh.size.x())});
        }
        s.prim_object[2].push_back(obj);
        break;
      }
      case ShapeType::cylinder:
        revolve(mesh, p, {{sh.size.x(), -sh.size.y()}, {sh.size.x(), sh.size.y()}}, segs, obj);
        break;
      case ShapeType::cone: revolve(mesh, p, {{sh.size.x(), -sh.size.y()}, {0.0, sh.size.y()}}, segs, obj); break;
      case ShapeType::ellipsoid: {
        // A unit UV sphere scaled by the radii (a linear map keeps the vertices on the ellipsoid).
        std::vector<std::pair<double, double>> rings;
        const int n_rings = std::max(2, segs / 2);
        for (int k = 1; k < n_rings; ++k) {
          const double a = M_PI * k / n_rings;
          rings.push_back({std::sin(a), -std::cos(a)});
        }
        Pose scaled = p;
        Mesh unit;
        revolve(unit, Pose{}, rings, segs, obj);
        // Poles: fans to the two axis points instead of the flat caps of revolve().
        const std::uint32_t base = static_cast<std::uint32_t>(mesh.vertices.size() / 3);
        for (std::size_t v = 0; v < unit.vertices.size(); v += 3)
          mesh.vertex(scaled, V(unit.vertices[v], unit.vertices[v + 1], unit.vertices[v + 2]).cwiseProduct(sh.size));
        const std::size_t ring_tris = 2 * std::size_t(segs) * (rings.size() - 1);
        for (std::size_t t = 0; t < ring_tris; ++t)
          mesh.triangle(base + unit.indices[3 * t], base + unit.indices[3 * t + 1], base + unit.indices[3 * t + 2], obj);
        const std::uint32_t south = mesh.vertex(p, V(0, 0, -sh.size.z())), north = mesh.vertex(p, V(0, 0, sh.size.z()));
        const std::uint32_t last = base + static_cast<std::uint32_t>((rings.size() - 1) * segs);
        for (int s2 = 0; s2 < segs; ++s2) {
          const std::uint32_t t2 = (s2 + 1) % segs;
          mesh.triangle(south, base + t2, base + s2, obj);
          mesh.triangle(north, last + s2, last + t2, obj);
        }
        break;
      }
      case ShapeType::halfspace: break;
    }
  }
  if (!mesh.object.empty()) {
    RTCGeometry g = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), mesh.vertices.size() / 3));
    std::copy(mesh.vertices.begin(), mesh.vertices.end(), v);
    auto* ix = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(std::uint32_t), mesh.object.size()));
    std::copy(mesh.indices.begin(), mesh.indices.end(), ix);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(s.scene, g, 0);
    rtcReleaseGeometry(g);
    s.prim_object[0] = std::move(mesh.object);
  }
  if (!spheres.empty()) {
    RTCGeometry g = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                          4 * sizeof(float), spheres.size() / 4));
    std::copy(spheres.begin(), spheres.end(), v);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(s.scene, g, 1);
    rtcReleaseGeometry(g);
  }
  if (!curves.empty()) {
    const std::size_t n = curves.size() / 8;
    RTCGeometry g = rtcNewGeometry(s.device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    auto* v = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 2 * n));
    std::copy(curves.begin(), curves.end(), v);
    auto* ix = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(std::uint32_t), n));
    for (std::size_t k = 0; k < n; ++k) ix[k] = static_cast<std::uint32_t>(2 * k);
    // No neighbours on either side: both ends get their spherical caps (a capsule).
    auto* flags = static_cast<std::uint8_t*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_FLAGS, 0, RTC_FORMAT_UCHAR, sizeof(std::uint8_t), n));
    std::fill(flags, flags + n, std::uint8_t(0));
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(s.scene, g, 2);
    rtcReleaseGeometry(g);
  }
  s.triangles = s.prim_object[0].size();
  const auto commit_start = std::chrono::steady_clock::now();
  rtcCommitScene(s.scene);
  BuildTimes times;
  times.commit_ms = ms_since(commit_start);
  times.total_ms = ms_since(start);
  return times;
}

void EmbreeRayScene::cast(const RayBatch& rays, bool any, int threads, EmbreeHits& out) const {
  const Impl& s = *impl_;
  if (!s.scene) throw InputError("EmbreeRayScene::cast: build() first");
  const std::size_t n = rays.size();
  out.hit.assign(n, 0);
  out.t.assign(n, std::nan(""));
  out.object.assign(n, std::numeric_limits<std::uint32_t>::max());
  out.nx.assign(n, 0.f), out.ny.assign(n, 0.f), out.nz.assign(n, 0.f);
  const auto body = [&](const tbb::blocked_range<std::size_t>& r) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (std::size_t i = r.begin(); i < r.end(); ++i) {
      const double dx = rays.direction.x[i], dy = rays.direction.y[i], dz = rays.direction.z[i];
      const bool valid = std::isfinite(rays.origin.x[i]) && std::isfinite(rays.origin.y[i]) &&
                         std::isfinite(rays.origin.z[i]) && std::isfinite(dx) && std::isfinite(dy) &&
                         std::isfinite(dz) && dx * dx + dy * dy + dz * dz > 0 && rays.t_max[i] >= 0;
      if (!valid) continue;
      RTCRayHit rh{};
      rh.ray.org_x = float(rays.origin.x[i]), rh.ray.org_y = float(rays.origin.y[i]);
      rh.ray.org_z = float(rays.origin.z[i]);
      rh.ray.dir_x = float(dx), rh.ray.dir_y = float(dy), rh.ray.dir_z = float(dz);
      rh.ray.tnear = 0.f;
      rh.ray.tfar = float(std::min<double>(rays.t_max[i], std::numeric_limits<float>::infinity()));
      rh.ray.mask = 0xffffffffu;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      if (any) {
        rtcOccluded1(s.scene, &context, &rh.ray);
        out.hit[i] = rh.ray.tfar < 0.f;  // Embree sets tfar = -inf on a hit
        continue;
      }
      rtcIntersect1(s.scene, &context, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
      out.hit[i] = 1;
      out.t[i] = rh.ray.tfar;
      out.object[i] = s.prim_object[rh.hit.geomID][rh.hit.primID];
      out.nx[i] = rh.hit.Ng_x, out.ny[i] = rh.hit.Ng_y, out.nz[i] = rh.hit.Ng_z;
    }
  };
  const auto run = [&] { tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), body); };
  if (threads <= 0) {
    run();
  } else {
    tbb::task_arena arena(threads);
    arena.execute(run);
  }
}

}  // namespace batchcol::peers
