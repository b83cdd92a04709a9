// `batchcol rays`: times ray queries. Scene mode: builds a scene (hulls or mixed primitives), times the LBVH build,
// its refit after every object moved, and the rays per second of the query; with --peers, the same scene and rays in
// Embree 3 (build and rays/s) and the agreement of the closest hits. Shape mode: rays against one posed shape each
// (sphere, box, capsule, hull), double and float. --batch FILE casts the "rays" of a batch file; --scene FILE casts
// the "rays" of a batch file with "objects" against those objects, timed as the generated scenes. --out writes the
// hits as CSV.
#include "cli/atomic_output.hpp"
#include "cli/commands.hpp"
#include "testkit/portable_random.hpp"
#include "testkit/rays_scene.hpp"

#include "peers/embree_rays.hpp"

#include <batchcol/io.hpp>
#include <batchcol/rays.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

namespace batchcol::cli {
namespace {

using testkit::make_crossing_rays;
using testkit::make_rays_scene;
using testkit::move_objects;
using testkit::PortableRandom;
using testkit::RaysScene;
using testkit::RaysSceneSpec;

struct RaysSettings {
  RaysSceneSpec scene;
  std::string mode = "scene", query = "closest", out, batch, scene_file, isa = "auto";
  std::int64_t rays = 1000000;
  int threads = 0, runs = 3, frames = 5, segments = 64;
  bool json = false, peers = false;
};

void check(bool ok, const std::string& message) {
  if (!ok) throw InputError(message);
}

void validate(const RaysSettings& s) {
  check(s.mode == "scene" || s.mode == "shape", "--mode " + s.mode + ": unknown (valid: scene, shape)");
  check(s.scene.objects >= 1 && s.scene.objects < (std::int64_t{1} << 31),
        "--objects must be in [1, 2^31) (got " + std::to_string(s.scene.objects) + ")");
  check(s.rays >= 1 && s.rays < (std::int64_t{1} << 31), "--rays must be in [1, 2^31) (got " + std::to_string(s.rays) + ")");
  check(s.scene.shapes == "hull" || s.scene.shapes == "mixed", "--shapes " + s.scene.shapes + ": unknown (valid: hull, mixed)");
  check(s.scene.hull_vertices >= 4, "--hull-vertices must be >= 4 (got " + std::to_string(s.scene.hull_vertices) + ")");
  check(std::isfinite(s.scene.fill) && s.scene.fill > 0, "--fill must be a finite number > 0");
  check(s.threads >= 0, "--threads must be >= 0 (0 = all cores)");
  check(s.runs >= 1, "--runs must be >= 1");
  check(s.frames >= 1, "--frames must be >= 1");
  check(s.segments >= 3, "--segments must be >= 3");
  check(s.out.empty() || s.mode == "scene" || !s.batch.empty(), "--out is only available with --mode scene or --batch");
  check(s.scene_file.empty() || s.mode == "scene", "--scene casts against a scene: it cannot be used with --mode shape");
  check(s.query == "closest" || s.query == "any" || s.query == "all",
        "--query " + s.query + ": unknown (valid: closest, any, all)");
  check(s.isa == "auto" || s.isa == "scalar" || s.isa == "avx2" || s.isa == "avx512",
        "--isa " + s.isa + ": unknown instruction set (valid: auto, scalar, avx2, avx512)");
  check(!s.peers || peers::have_embree(), "--peers needs Embree 3 (install libembree-dev and rebuild)");
}

// The instruction set the casts run (resolved: InputError when this CPU cannot run the one asked for).
InstructionSet ray_isa(const RaysSettings& s) {
  return resolve_instruction_set(s.isa == "auto" ? InstructionSet::automatic : parse_instruction_set(s.isa));
}

double time_ms(const std::function<void()>& f) {
  const auto start = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void write_hits_csv(const RayResults& r, RayQuery q, std::ostream& out) {
  out.precision(17);
  if (q == RayQuery::all) {
    out << "ray,t,object_slot,object_generation,n_x,n_y,n_z\n";
    for (std::size_t i = 0; i < r.size(); ++i)
      for (std::uint64_t k = r.hit_begin[i]; k < r.hit_begin[i + 1]; ++k)
        out << i << ',' << r.all_t[k] << ',' << r.all_object[k].slot << ',' << r.all_object[k].generation << ','
            << r.all_normal.x[k] << ',' << r.all_normal.y[k] << ',' << r.all_normal.z[k] << '\n';
    return;
  }
  out << "ray,status,hit,t,object_slot,object_generation,n_x,n_y,n_z\n";
  for (std::size_t i = 0; i < r.size(); ++i) {
    out << i << ',' << to_string(r.status[i]) << ',' << int(r.hit[i]) << ',';
    if (r.hit[i]) {
      out << r.t[i] << ',';
      if (!r.object.empty()) out << r.object[i].slot << ',' << r.object[i].generation;
      else out << ',';
      out << ',' << r.normal.x[i] << ',' << r.normal.y[i] << ',' << r.normal.z[i] << '\n';
    } else {
      out << ",,,,,\n";
    }
  }
}

// The scene and rays: generated, or from a scene file (objects + rays).
struct SceneInput {
  RaysScene world;
  RayBatch rays;
};

SceneInput scene_input(const RaysSettings& s) {
  if (s.scene_file.empty()) {
    RaysScene world = make_rays_scene(s.scene);
    RayBatch rays = make_crossing_rays(s.rays, world.half_extent, s.scene.seed);
    return {std::move(world), std::move(rays)};
  }
  BatchFile file = load_batch_file(s.scene_file);
  check(file.has_objects, s.scene_file + R"(: the file has no "objects" (a scene file places shapes as "objects": )"
                                         R"([{"shape": i, "pose": {...}}]; --batch casts rays against posed shapes))");
  check(file.scene_rays.size() > 0, s.scene_file + R"(: the file has no "rays")");
  RayBatch rays = std::move(file.scene_rays);
  return {make_rays_scene(std::move(file)), std::move(rays)};
}

nlohmann::json run_scene_mode(const RaysSettings& s, RayResults& results) {
  const RayQuery query = parse_ray_query(s.query);
  SceneInput input = scene_input(s);
  RaysScene& world = input.world;
  const RayBatch& rays = input.rays;
  const std::size_t n_rays = rays.size();
  std::vector<Pose> file_poses;  // a file's scene is cast as given: its poses come back after the refit frames
  if (!s.scene_file.empty())
    for (ObjectHandle h : world.handles) file_poses.push_back(world.scene->pose(h));
  RaySceneIndex index;
  std::vector<double> build, boxes, refit, collapse, wide_refit;
  for (int r = 0; r < s.runs; ++r) {
    index.update(*world.scene, s.threads, true);
    build.push_back(index.timings().total_ms);
    boxes.push_back(index.timings().boxes_ms);
    collapse.push_back(index.timings().wide_ms);
  }
  for (int f = 0; f < s.frames; ++f) {
    move_objects(world, 0.01, s.scene.seed + 100 + f);
    index.update(*world.scene, s.threads);
    refit.push_back(index.timings().total_ms);
    wide_refit.push_back(index.timings().wide_ms);
  }
  if (!file_poses.empty()) {
    for (std::size_t k = 0; k < file_poses.size(); ++k) world.scene->set_pose(world.handles[k], file_poses[k]);
    index.update(*world.scene, s.threads);
  }
  RayOptions options;
  options.query = query;
  options.threads = s.threads;
  options.isa = ray_isa(s);
#ifdef BATCHCOL_HAVE_EMBREE
  // Embree's scene is built before the timed casts, whose runs then alternate between the two libraries so that
  // both see the same machine load (the ratio is what the report is for; the machine may be shared).
  std::unique_ptr<peers::EmbreeRayScene> embree;
  std::vector<double> commit, total, ecast;
  peers::EmbreeHits theirs;
  const bool any = query == RayQuery::any;
  if (s.peers) {
    std::vector<peers::EmbreeObject> objects;
    for (ObjectHandle h : world.handles) objects.push_back({&(*world.table)[world.scene->shape(h)], world.scene->pose(h)});
    embree = std::make_unique<peers::EmbreeRayScene>(s.threads);
    for (int r = 0; r < s.runs; ++r) {
      const auto t = embree->build(objects, {s.segments});
      commit.push_back(t.commit_ms), total.push_back(t.total_ms);
    }
  }
#endif
  std::vector<double> cast;
  for (int r = 0; r < s.runs; ++r) {
    cast.push_back(time_ms([&] { index.cast(rays, options, results); }));
#ifdef BATCHCOL_HAVE_EMBREE
    if (embree) ecast.push_back(time_ms([&] { embree->cast(rays, any, s.threads, theirs); }));
#endif
  }
  std::size_t hits = 0, all_rows = results.all_t.size();
  for (std::uint8_t h : results.hit) hits += h;
  const double cast_ms = median(cast);
  nlohmann::json j = {{"mode", "scene"},
                      {"shapes", s.scene_file.empty() ? s.scene.shapes : "file"},
                      {"objects", world.handles.size()},
                      {"rays", n_rays},
                      {"query", s.query},
                      {"threads", s.threads},
                      {"isa", to_string(ray_isa(s))},
                      {"hit_fraction", double(hits) / double(n_rays)},
                      {"batchcol",
                       {{"build_ms", median(build)},
                        {"build_boxes_ms", median(boxes)},
                        {"build_wide_collapse_ms", median(collapse)},
                        {"refit_ms", median(refit)},
                        {"refit_wide_ms", median(wide_refit)},
                        {"cast_ms", cast_ms},
                        {"rays_per_s", double(n_rays) / (cast_ms * 1e-3)}}}};
  if (!s.scene_file.empty()) j["scene_file"] = s.scene_file;
  if (query == RayQuery::all) j["all_hit_rows"] = all_rows;
#ifdef BATCHCOL_HAVE_EMBREE
  if (embree) {
    // Agreement on the closest hit: same hit/miss, same object (slots are the insertion order of a fresh scene),
    // t within 1e-6 relative.
    // Grazing rays (|cos| < 0.05 between the ray and our normal) turn Embree's float vertex rounding (~1e-7 of the
    // scene's coordinates) into t errors 20x larger: counted apart.
    std::size_t same_hit = 0, same_object = 0, close_t = 0, steep = 0, steep_close_t = 0;
    double max_rel_steep = 0.0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      if (results.hit[i] != theirs.hit[i]) continue;
      ++same_hit;
      if (!results.hit[i] || any || query == RayQuery::all) continue;
      if (results.object[i].slot != theirs.object[i]) continue;
      ++same_object;
      const double rel = std::abs(results.t[i] - theirs.t[i]) / results.t[i];
      if (rel <= 1e-6) ++close_t;
      const double cosine = std::abs(results.normal[i].dot(rays.direction[i])) / rays.direction[i].norm();
      if (cosine >= 0.05) {
        ++steep;
        if (rel <= 1e-6) ++steep_close_t;
        max_rel_steep = std::max(max_rel_steep, rel);
      }
    }
    const double ems = median(ecast);
    j["embree"] = {{"triangles", embree->triangle_count()},
                   {"segments", s.segments},
                   {"build_ms", median(commit)},
                   {"build_with_tessellation_ms", median(total)},
                   {"cast_ms", ems},
                   {"rays_per_s", double(n_rays) / (ems * 1e-3)},
                   {"same_hit_or_miss", same_hit},
                   {"same_object", same_object},
                   {"t_within_1e-6_relative", close_t},
                   {"non_grazing_same_object", steep},
                   {"non_grazing_t_within_1e-6_relative", steep_close_t},
                   {"non_grazing_max_relative_t_difference", max_rel_steep}};
    j["ratio_rays_per_s"] = ems / cast_ms;
    j["ratio_build"] = median(commit) / median(build);
  }
#endif
  return j;
}

nlohmann::json run_shape_mode(const RaysSettings& s) {
  PortableRandom rng(s.scene.seed);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < s.scene.hull_vertices; ++i) points.push_back(0.5 * rng.unit_vector());
  ShapeTable table;
  const std::uint32_t ids[4] = {table.add(Shape::sphere(0.5)), table.add(Shape::box(0.4, 0.3, 0.2)),
                                table.add(Shape::capsule(0.25, 0.25)), table.add(Shape::convex(points))};
  const char* names[4] = {"sphere", "box", "capsule", "hull"};
  nlohmann::json j = {{"mode", "shape"}, {"rays", s.rays}, {"threads", s.threads}, {"isa", to_string(ray_isa(s))}, {"hull_vertices", s.scene.hull_vertices}};
  for (int k = 0; k < 4; ++k) {
    ShapeRayBatch batch;
    for (std::int64_t i = 0; i < s.rays; ++i) {
      const Pose pose{Eigen::Vector3d(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5)), rng.rotation()};
      const Eigen::Vector3d o = pose.translation + 3.0 * rng.unit_vector();
      const Eigen::Vector3d target = pose.translation + 0.6 * rng.unit_vector();
      batch.add(ids[k], pose, o, (target - o).normalized(), INFINITY);
    }
    for (Precision p : {Precision::float64, Precision::float32}) {
      RayOptions o;
      o.threads = s.threads;
      o.isa = ray_isa(s);
      o.precision = p;
      RayResults r;
      std::vector<double> ms;
      for (int run = 0; run < s.runs; ++run) ms.push_back(time_ms([&] { cast_rays(table, batch, o, r); }));
      std::size_t hits = 0;
      for (std::uint8_t h : r.hit) hits += h;
      j[names[k]][to_string(p)] = {{"cast_ms", median(ms)},
                                   {"rays_per_s", double(s.rays) / (median(ms) * 1e-3)},
                                   {"hit_fraction", double(hits) / double(s.rays)}};
    }
  }
  return j;
}

// The rays of a batch file (each against its own posed shape), through cast_rays().
nlohmann::json run_batch_mode(const RaysSettings& s, RayResults& results) {
  const BatchFile file = load_batch_file(s.batch);
  check(!file.has_objects, s.batch + R"(: the file has "objects", so its rays are scene rays: cast them with --scene)");
  check(file.rays.size() > 0, s.batch + ": the file has no \"rays\"");
  RayOptions options;
  options.threads = s.threads;
  options.isa = ray_isa(s);
  if (file.precision) options.precision = *file.precision;
  const double ms = time_ms([&] { cast_rays(file.shapes, file.rays, options, results); });
  std::size_t hits = 0;
  for (std::uint8_t h : results.hit) hits += h;
  return {{"mode", "batch"},
          {"rays", file.rays.size()},
          {"hits", hits},
          {"hit_fraction", double(hits) / double(file.rays.size())},
          {"cast_ms", ms}};
}

void print_text(const nlohmann::json& j) {
  if (j["mode"] == "batch") {
    std::cout << j["rays"] << " rays from the batch file, " << j["hits"] << " hits, " << j["cast_ms"] << " ms\n";
    return;
  }
  if (j["mode"] == "shape") {
    for (const char* n : {"sphere", "box", "capsule", "hull"})
      for (const char* p : {"double", "float"})
        std::cout << n << ' ' << p << ": " << j[n][p]["rays_per_s"].get<double>() / 1e6 << " M rays/s (hit fraction "
                  << j[n][p]["hit_fraction"].get<double>() << ")\n";
    return;
  }
  const auto& b = j["batchcol"];
  std::cout << j["objects"] << ' '
            << (j.contains("scene_file") ? "objects from " + j["scene_file"].get<std::string>()
                                         : j["shapes"].get<std::string>() + " objects")
            << ", " << j["rays"] << " rays, query "
            << j["query"].get<std::string>() << ", hit fraction " << j["hit_fraction"] << '\n'
            << "batchcol: build " << b["build_ms"] << " ms, refit " << b["refit_ms"] << " ms, "
            << b["rays_per_s"].get<double>() / 1e6 << " M rays/s\n";
  if (j.contains("embree")) {
    const auto& e = j["embree"];
    std::cout << "embree:   build " << e["build_ms"] << " ms (" << e["triangles"] << " triangles), "
              << e["rays_per_s"].get<double>() / 1e6 << " M rays/s; same hit/miss " << e["same_hit_or_miss"]
              << ", same object " << e["same_object"] << ", t within 1e-6 " << e["t_within_1e-6_relative"]
              << " (non-grazing: " << e["non_grazing_t_within_1e-6_relative"] << " of " << e["non_grazing_same_object"]
              << ", max relative difference " << e["non_grazing_max_relative_t_difference"] << ")\n"
              << "ratios (batchcol / embree): rays/s " << j["ratio_rays_per_s"] << ", build speed " << j["ratio_build"]
              << '\n';
  }
}

int run_rays(const RaysSettings& s) {
  validate(s);
  RayResults results;
  const nlohmann::json j = !s.batch.empty() ? run_batch_mode(s, results)
                           : s.mode == "scene" ? run_scene_mode(s, results)
                                               : run_shape_mode(s);
  if (!s.out.empty()) {
    const RayQuery query = s.batch.empty() ? parse_ray_query(s.query) : RayQuery::closest;
    write_file_atomically(s.out, [&](std::ostream& out) { write_hits_csv(results, query, out); });
  }
  if (s.json) std::cout << j.dump(2) << '\n';
  else print_text(j);
  if (!std::cout) throw InputError("writing to standard output failed");
  return 0;
}

}  // namespace

Command add_rays_command(CLI::App& parent) {
  auto s = std::make_shared<RaysSettings>();
  CLI::App* app = parent.add_subcommand("rays", "Time batched ray queries against a scene or posed shapes (Embree with --peers)");
  app->add_option("--mode", s->mode, "scene or shape (rays against one posed sphere/box/capsule/hull each)")->capture_default_str();
  app->add_option("--objects", s->scene.objects, "Scene objects (>= 1)")->capture_default_str();
  app->add_option("--rays", s->rays, "Rays (>= 1)")->capture_default_str();
  app->add_option("--shapes", s->scene.shapes, "hull or mixed (spheres, capsules, boxes, cylinders)")->capture_default_str();
  app->add_option("--hull-vertices", s->scene.hull_vertices, "Points per hull (on a sphere)")->capture_default_str();
  app->add_option("--fill", s->scene.fill, "Objects a ray crosses on average (sets the scene size)")->capture_default_str();
  app->add_option("--query", s->query, "closest, any or all")->capture_default_str();
  app->add_option("--threads", s->threads, "Worker threads (0 = all cores)")->capture_default_str();
  app->add_option("--isa", s->isa, "auto, scalar, avx2 or avx512: the traversal's and lane kernels' instruction set (auto: the best this CPU runs; same hits on every set)")->capture_default_str();
  app->add_option("--runs", s->runs, "Timed runs (the median is reported)")->capture_default_str();
  app->add_option("--frames", s->frames, "Refit frames (every object moves 1 cm)")->capture_default_str();
  app->add_option("--segments", s->segments, "Embree tessellation of cylinders (segments around)")->capture_default_str();
  app->add_option("--seed", s->scene.seed, "Seed of the scene and rays")->capture_default_str();
  app->add_option("--out", s->out, "Write the hits as CSV (scene mode or --batch)");
  CLI::Option* batch = app->add_option("--batch", s->batch, "Cast the \"rays\" of a batch file (each against its posed shape) instead");
  CLI::Option* scene = app->add_option("--scene", s->scene_file,
                                       "Cast the \"rays\" of a scene file (a batch file with \"objects\") against its objects");
  // The generator's settings mean nothing for a scene read from a file: refused rather than ignored.
  for (const char* name : {"--objects", "--rays", "--shapes", "--hull-vertices", "--fill", "--seed"})
    scene->excludes(app->get_option(name));
  scene->excludes(batch);
  app->add_flag("--json", s->json, "Print one JSON object");
  app->add_flag("--peers", s->peers, "Also build and cast with Embree 3 and compare the hits");
  return {app, [s] { return run_rays(*s); }};
}

}  // namespace batchcol::cli
