// libFuzzer target: mesh bytes -> temporary file -> load_mesh_points -> compute_convex_hull. The first byte picks
// the file extension (assimp chooses its importer by extension, then by content); the rest is the file. For an
// OBJ, the bytes after a line "%%MTL%%" become `material.mtl` next to it (corpus/mesh/tetra_mtl_obj): assimp's
// material reader crashed on such a library, so the loader now reads none; this keeps checking that. Any input
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

#include <sys/stat.h>
#include <unistd.h>

namespace {

const char* const kExtensions[] = {".stl", ".obj", ".ply", ".dae"};

std::string temp_dir() {
  const char* dir = std::getenv("TMPDIR");
  return std::string(dir ? dir : "/tmp") + "/batchcol_fuzz_mesh_" + std::to_string(::getpid());
}

void write_file(const std::string& path, const char* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(data, static_cast<std::streamsize>(size));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // BATCHCOL_FUZZ_MESH_EXT=.obj (or .stl, .ply, .dae) fuzzes one reader only, to tell which one misbehaves.
  const char* forced = std::getenv("BATCHCOL_FUZZ_MESH_EXT");
  const std::string extension = forced ? forced : kExtensions[data[0] % (sizeof kExtensions / sizeof kExtensions[0])];
  const std::string dir = temp_dir();
  ::mkdir(dir.c_str(), 0700);
  const std::string path = dir + "/mesh" + extension, material = dir + "/material.mtl";
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  std::string materials;
  const std::string marker = "\n%%MTL%%\n";
  if (extension == ".obj") {
    const std::size_t at = bytes.find(marker);
    if (at != std::string::npos) {
      materials = bytes.substr(at + marker.size());
      bytes.resize(at + 1);
    }
  }
  write_file(path, bytes.data(), bytes.size());
  write_file(material, materials.data(), materials.size());
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
  std::remove(material.c_str());
  return 0;
}
