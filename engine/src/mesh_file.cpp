// Mesh input through assimp: only the vertex positions are kept (the caller takes their convex hull).
#include "batchcol/io.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#ifdef BATCHCOL_HAVE_ASSIMP
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#endif

namespace batchcol {

std::vector<Eigen::Vector3d> load_mesh_points(const std::string& path) {
  namespace fs = std::filesystem;
  const std::string what = "mesh '" + path + "'";
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(what + ": no such file");
  if (fs::is_directory(status)) throw InputError(what + ": is a directory, expected a mesh file");
  if (!fs::is_regular_file(status)) throw InputError(what + ": not a regular file");
  if (!std::ifstream(path, std::ios::binary)) throw InputError(what + ": cannot open the file for reading");

#ifdef BATCHCOL_HAVE_ASSIMP
  Assimp::Importer importer;
  // Points only: joining duplicates shrinks STL meshes (3 copies per vertex) before the hull is computed.
  const aiScene* scene = importer.ReadFile(path, aiProcess_JoinIdenticalVertices);
  if (scene == nullptr) throw InputError(what + ": cannot read: " + importer.GetErrorString());

  std::vector<Eigen::Vector3d> points;
  std::size_t faces = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    faces += mesh->mNumFaces;
    for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
      const aiVector3D& v = mesh->mVertices[i];
      const Eigen::Vector3d p(v.x, v.y, v.z);
      if (!p.allFinite()) {
        throw InputError(what + ": vertex " + std::to_string(i) + " of mesh " + std::to_string(m) + " is not finite");
      }
      points.push_back(p);
    }
  }
  if (points.empty() || faces == 0) throw InputError(what + ": the file holds no vertices or no faces");
  return points;
#else
  throw InputError(what + ": mesh support needs assimp (apt-get install libassimp-dev)");
#endif
}

}  // namespace batchcol
