// libFuzzer target: mesh bytes -> temporary file -> load_mesh_points -> compute_convex_hull. The first byte picks
// the file extension (assimp chooses its importer by extension, then by content); the rest is the file. Any input
// must either load or throw InputError; crashes, sanitizer reports, hangs and other exceptions are bugs.
#include "batchcol/io.hpp"
#include "batchcol/shapes.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include <unistd.h>

namespace {

const char* const kExtensions[] = {".stl", ".obj", ".ply", ".dae"};

std::string temp_path(const char* extension) {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/batchcol_fuzz_mesh_" + std::to_string(::getpid()) + extension;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // BATCHCOL_FUZZ_MESH_EXT=.obj (or .stl, .ply, .dae) fuzzes one reader only, to tell which one misbehaves.
  const char* forced = std::getenv("BATCHCOL_FUZZ_MESH_EXT");
  const std::string path = temp_path(forced ? forced : kExtensions[data[0] % (sizeof kExtensions / sizeof kExtensions[0])]);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const auto points = batchcol::load_mesh_points(path);
    const auto hull = batchcol::compute_convex_hull(points, "mesh");
    // An accepted hull is a real 3D polytope with valid indices.
    if (hull->vertices.size() < 4 || hull->faces.size() < 4) __builtin_trap();
    for (const auto& f : hull->faces)
      for (std::uint32_t v : f)
        if (v >= hull->vertices.size()) __builtin_trap();
    for (const auto& n : hull->face_normals)
      if (!n.allFinite() || std::abs(n.norm() - 1.0) > 1e-9) __builtin_trap();
    if (!std::isfinite(hull->radius) || !hull->centroid.allFinite()) __builtin_trap();
  } catch (const batchcol::InputError&) {
  }
  std::remove(path.c_str());
  return 0;
}
