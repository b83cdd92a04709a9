// Mesh input through assimp (OBJ, STL, PLY, COLLADA): only the vertex positions are kept, in the file's world frame
// (the caller takes their convex hull).
//
// Assimp is lenient with broken files and some of its readers crash or hang on them (found by tools/fuzz), so:
// the path must be a readable, non-empty regular file with a supported extension; a binary STL must have exactly
// 84 + 50 * count bytes and finite coordinates; a PLY file must hold exactly what its header declares (mesh_ply.cpp);
// assimp reads the mesh from memory and opens no file (not an OBJ's material libraries); only the readers of the
// supported formats are registered; a COLLADA file's declared counts and index lists must fit its size
// (check_collada); no assimp post-processing runs (its steps trust the file's face indices); every vertex must be
// finite. Each problem is one InputError naming the file.
#include "batchcol/io.hpp"

#include "mesh_checks.hpp"
#include "printable.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#ifdef BATCHCOL_HAVE_ASSIMP
#include <assimp/BaseImporter.h>
#include <assimp/DefaultIOStream.h>
#include <assimp/DefaultIOSystem.h>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/importerdesc.h>
#include <assimp/scene.h>
#endif

namespace batchcol {
namespace {

namespace fs = std::filesystem;

constexpr std::uint64_t kStlHeaderBytes = 84;    // 80-byte comment + uint32 triangle count
constexpr std::uint64_t kStlTriangleBytes = 50;  // normal + 3 vertices (12 floats) + uint16 attribute

/// Checks that `path` names a readable, non-empty regular file and returns its size in bytes.
std::uint64_t checked_file_size(const std::string& path, const std::string& what) {
  if (path.empty()) throw InputError(what + ": empty file name");
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  // ENOTDIR (a parent in the path is a file) also reads as "not found": report it as what it is.
  if (ec && ec != std::errc::no_such_file_or_directory) throw InputError(what + ": cannot access the file: " + ec.message());
  if (status.type() == fs::file_type::not_found) throw InputError(what + ": no such file");
  if (fs::is_directory(status)) throw InputError(what + ": is a directory, expected a mesh file");
  if (!fs::is_regular_file(status)) throw InputError(what + ": not a regular file (a FIFO, device or socket)");
  errno = 0;
  if (!std::ifstream(path, std::ios::binary)) {
    throw InputError(what + ": cannot open the file for reading" + (errno ? ": " + std::string(std::strerror(errno)) : ""));
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw InputError(what + ": cannot read the file size: " + ec.message());
  if (size == 0) throw InputError(what + ": the file is empty (0 bytes)");
  return size;
}

std::string read_bytes(const std::string& path, std::uint64_t count, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes(count, '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(count))) throw InputError(what + ": read error");
  return bytes;
}

/// An ASCII STL starts with "solid" and holds text only; a binary STL's 80-byte comment may also start with "solid",
/// but its float data is not text. The first 512 bytes decide.
bool looks_like_ascii_stl(const std::string& head) {
  const std::size_t start = head.find_first_not_of(" \t\r\n");
  if (start == std::string::npos || head.compare(start, 5, "solid") != 0) return false;
  return std::all_of(head.begin(), head.end(), [](unsigned char c) { return c == '\t' || c == '\n' || c == '\r' || (c >= 32 && c < 127); });
}

std::uint32_t little_endian_u32(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(i)]);
  return v;
}

float little_endian_f32(const std::string& bytes, std::size_t at) {
  const std::uint32_t bits = little_endian_u32(bytes, at);
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

/// Binary STL: size = 84 + 50 * count exactly, count > 0, every vertex finite. ASCII STL is left to assimp.
void check_stl(const std::string& path, std::uint64_t size, const std::string& what) {
  const std::string head = read_bytes(path, std::min<std::uint64_t>(size, 512), what);
  if (looks_like_ascii_stl(head)) return;
  if (size < kStlHeaderBytes) {
    throw InputError(what + ": truncated binary STL: " + std::to_string(size) + " bytes, shorter than the " +
                     std::to_string(kStlHeaderBytes) + "-byte header");
  }
  const std::uint64_t count = little_endian_u32(head, 80);
  const std::uint64_t expected = kStlHeaderBytes + kStlTriangleBytes * count;
  if (size != expected) {
    throw InputError(what + ": binary STL is truncated or its triangle count is wrong: the header declares " +
                     std::to_string(count) + " triangles (84 + 50 x " + std::to_string(count) + " = " +
                     std::to_string(expected) + " bytes) but the file has " + std::to_string(size) + " bytes");
  }
  if (count == 0) throw InputError(what + ": binary STL with zero triangles (no faces)");
  const std::string bytes = read_bytes(path, size, what);
  for (std::uint64_t t = 0; t < count; ++t)
    for (int k = 0; k < 9; ++k) {  // skip the 3 normal floats, check the 9 vertex coordinates
      const std::size_t at = kStlHeaderBytes + kStlTriangleBytes * t + 12 + 4 * static_cast<std::size_t>(k);
      if (!std::isfinite(little_endian_f32(bytes, at))) {
        throw InputError(what + ": binary STL triangle " + std::to_string(t) + " has a non-finite coordinate");
      }
    }
}

/// COLLADA: assimp 5.2.5 trusts the numbers a COLLADA file declares (found by fuzzing, tools/fuzz/known/):
/// a non-digit inside an index list (`<p>1 2"3</p>`) makes its index reader loop, appending until ~19 GB are
/// allocated; a `count` of 3e9 or a `vcount` entry of 3e8 is reserved as is (std::bad_alloc after minutes of
/// swapping); a `stride` of 3e8 crashes it (SEGV). So before assimp reads the file:
/// - the index lists <p>, <vcount>, <v>, <h> must hold only unsigned integers and whitespace;
/// - every `count`, `stride`, `offset` and `set` attribute, every index, each list's vcount sum and an accessor's
///   count x stride must be at most half the file size: each thing counted is at least one digit and one
///   separator of this very file (offsets and sets index the <input> tags, which are longer still).
/// A file passing these checks makes assimp allocate in proportion to the file's size.
void check_collada(const std::string& path, std::uint64_t size, const std::string& what) {
  const std::string text = read_bytes(path, size, what);
  const std::uint64_t limit = size / 2;
  const auto is_space = [&](std::size_t i) { return std::isspace(static_cast<unsigned char>(text[i])) != 0; };
  const auto line_of = [&](std::size_t at) {
    return std::to_string(1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  };
  const auto fail = [&](std::size_t at, const std::string& problem) {
    throw InputError(what + ": COLLADA line " + line_of(at) + ": " + problem);
  };
  // An unsigned decimal of at most 18 digits (fits in 64 bits) bounded by `limit`.
  const auto bounded = [&](const std::string& digits, std::size_t at, const std::string& name) {
    if (digits.empty() || digits.size() > 18 || digits.find_first_not_of("0123456789") != std::string::npos)
      fail(at, name + " '" + digits.substr(0, 40) + "' is not an unsigned integer");
    const std::uint64_t v = std::stoull(digits);
    if (v > limit) {
      fail(at, name + " " + digits + " is more than this " + std::to_string(size) + "-byte file can hold (at most " +
                   std::to_string(limit) + ")");
    }
    return v;
  };
  for (std::size_t at = text.find('<'); at != std::string::npos; at = text.find('<', at + 1)) {
    // Comments, CDATA and processing instructions hold no markup: skip them whole.
    using Delimiters = std::pair<const char*, const char*>;
    for (const auto& [open, close] : {Delimiters{"<!--", "-->"}, Delimiters{"<![CDATA[", "]]>"}, Delimiters{"<?", "?>"}}) {
      if (text.compare(at, std::strlen(open), open) != 0) continue;
      const std::size_t end = text.find(close, at);
      if (end == std::string::npos) return;  // unterminated: assimp's XML parser refuses the file
      at = end;
      break;
    }
    if (text[at] != '<' || at + 1 >= text.size() || text[at + 1] == '/' || text[at + 1] == '!') continue;
    std::size_t end = at + 1;
    while (end < text.size() && !is_space(end) && text[end] != '>' && text[end] != '/') ++end;
    const std::string tag = text.substr(at + 1, end - at - 1);
    // Attributes: name, optional spaces, '=', optional spaces, a quoted value; up to the tag's '>'.
    std::uint64_t count = 0, stride = 1;
    std::size_t close = end;
    const auto skip_spaces = [&] { while (close < text.size() && is_space(close)) ++close; };
    while (true) {
      skip_spaces();
      if (close >= text.size()) return;  // unterminated tag: assimp's XML parser refuses the file
      if (text[close] == '>' || text[close] == '/') break;
      const std::size_t name_start = close;
      while (close < text.size() && !is_space(close) && text[close] != '=' && text[close] != '>') ++close;
      const std::string name = text.substr(name_start, close - name_start);
      skip_spaces();
      if (close >= text.size() || text[close] != '=') return;  // malformed XML: assimp refuses it
      ++close;
      skip_spaces();
      if (close >= text.size() || (text[close] != '"' && text[close] != '\'')) return;
      const std::size_t value_end = text.find(text[close], close + 1);
      if (value_end == std::string::npos) return;
      const std::string value = text.substr(close + 1, value_end - close - 1);
      close = value_end + 1;
      if (name != "count" && name != "stride" && name != "offset" && name != "set") continue;
      const std::uint64_t v = bounded(value, at, "<" + tag + "> " + name);
      if (name == "count") count = v;
      if (name == "stride") stride = v;
    }
    close = text.find('>', close);
    if (close == std::string::npos) return;
    if (tag == "accessor" && stride > 0 && count > limit / stride)
      fail(at, "<accessor> count x stride = " + std::to_string(count) + " x " + std::to_string(stride) +
                   " values, more than this file can hold");
    if (tag != "p" && tag != "vcount" && tag != "v" && tag != "h") continue;
    if (text[close - 1] == '/') continue;  // an empty <p/>
    const std::size_t content = close + 1, content_end = text.find('<', content);
    if (content_end == std::string::npos || text.compare(content_end, tag.size() + 2, "</" + tag) != 0)
      fail(at, "<" + tag + "> must hold only unsigned integers");
    std::uint64_t sum = 0;
    for (std::size_t i = content; i < content_end;) {
      if (is_space(i)) { ++i; continue; }
      std::size_t j = i;
      while (j < content_end && !is_space(j)) ++j;
      sum += bounded(text.substr(i, j - i), at, "<" + tag + "> entry");  // each <= limit: the sum cannot overflow
      i = j;
    }
    if (tag == "vcount" && sum > limit)
      fail(at, "<vcount> sums to " + std::to_string(sum) + " vertices, more than this file can hold");
  }
}

constexpr const char* kSupportedList = ".obj, .stl, .ply, .dae";

std::string lowercase_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext;
}

bool is_supported_extension(const std::string& ext) {
  return ext == ".obj" || ext == ".stl" || ext == ".ply" || ext == ".dae";
}

#ifdef BATCHCOL_HAVE_ASSIMP
/// Assimp picks a reader by content as well as by extension, and some of its ~50 readers crash on broken input
/// (the OFF reader did within seconds of fuzzing). Only the readers of the supported formats stay registered.
void keep_only_supported_readers(Assimp::Importer& importer) {
  for (std::size_t i = importer.GetImporterCount(); i-- > 0;) {
    const aiImporterDesc* desc = importer.GetImporterInfo(i);
    const std::string name = desc && desc->mFileExtensions ? desc->mFileExtensions : "";
    if (name == "obj" || name == "ply" || name.rfind("stl", 0) == 0 || name.rfind("dae", 0) == 0) continue;
    Assimp::BaseImporter* reader = importer.GetImporter(i);
    if (importer.UnregisterLoader(reader) == aiReturn_SUCCESS) delete reader;  // unregistering returns ownership
  }
}

/// Assimp opens more files than the one it is given (an OBJ's `mtllib` material libraries, and `<mesh>.mtl` when
/// one is missing): one naming a FIFO blocked the load forever, a device could be read without end, and assimp
/// 5.2.5's material reader writes through a null pointer on a library whose first statement is a texture map before
/// any `newmtl` (found by fuzzing; seed tools/fuzz/corpus/mesh/obj_mtl_texture_before_newmtl), also when the OBJ
/// names itself as its library. Only points are used here, so assimp reads the mesh from our memory buffer under
/// one reserved name, and this file system opens nothing else (assimp's own ReadFileFromMemory would not do: its
/// file system answers every name that starts with its magic one, and the OBJ reader's fallback `<mesh>.mtl` does).
/// A refused material library is a missing one to assimp's OBJ reader, which then uses its default material.
class MeshInMemory final : public Assimp::DefaultIOSystem {
 public:
  MeshInMemory(std::string name, const std::string& bytes) : name_(std::move(name)), bytes_(bytes) {}
  bool Exists(const char* file) const override { return file != nullptr && name_ == file; }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    if (file == nullptr || name_ != file || mode == nullptr || mode[0] != 'r') return nullptr;
    return new Assimp::MemoryIOStream(reinterpret_cast<const std::uint8_t*>(bytes_.data()), bytes_.size());
  }

 private:
  std::string name_;
  const std::string& bytes_;
};

/// The reserved name (plus the extension) the mesh is read under: a file that contains it is refused, so no
/// `mtllib` can name the mesh itself.
constexpr const char* kMemoryMeshName = "batchcol_mesh_in_memory";

/// Every vertex of every mesh a node refers to, in the file's world frame (the node transforms composed from the
/// root: COLLADA places meshes and carries its unit scale there), duplicates removed. Iterative: a deep node
/// hierarchy must not overflow the stack.
std::vector<Eigen::Vector3d> scene_points(const aiScene& scene, const std::string& what) {
  std::vector<Eigen::Vector3d> points;
  std::size_t faces = 0;
  const auto to_affine = [](const aiMatrix4x4& m) {
    Eigen::Matrix4d a;
    a << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
    return Eigen::Affine3d(a);
  };
  std::vector<std::pair<const aiNode*, Eigen::Affine3d>> stack;
  if (scene.mRootNode) stack.emplace_back(scene.mRootNode, to_affine(scene.mRootNode->mTransformation));
  while (!stack.empty()) {
    const auto [node, transform] = stack.back();
    stack.pop_back();
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const unsigned m = node->mMeshes[k];
      if (m >= scene.mNumMeshes || scene.mMeshes[m] == nullptr) continue;
      const aiMesh& mesh = *scene.mMeshes[m];
      faces += mesh.mNumFaces;
      for (unsigned i = 0; i < mesh.mNumVertices; ++i) {
        const aiVector3D& v = mesh.mVertices[i];
        const Eigen::Vector3d p = transform * Eigen::Vector3d(v.x, v.y, v.z);
        if (!p.allFinite()) {
          throw InputError(what + ": vertex " + std::to_string(i) + " of mesh " + std::to_string(m) + " is not finite");
        }
        points.push_back(p);
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c)
      if (node->mChildren[c]) stack.emplace_back(node->mChildren[c], transform * to_affine(node->mChildren[c]->mTransformation));
  }
  if (points.empty()) throw InputError(what + ": the file holds no vertices");
  if (faces == 0) throw InputError(what + ": the file holds " + std::to_string(points.size()) + " vertices but zero faces");
  // STL repeats every vertex once per triangle: remove exact duplicates before the hull.
  const auto less = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3);
  };
  std::sort(points.begin(), points.end(), less);
  points.erase(std::unique(points.begin(), points.end()), points.end());
  return points;
}
#endif

}  // namespace

std::vector<Eigen::Vector3d> load_mesh_points(const std::string& path) {
  const std::string what = "mesh '" + detail::printable(path, 200) + "'";
  const std::uint64_t size = checked_file_size(path, what);
  const std::string extension = lowercase_extension(path);
  if (!is_supported_extension(extension)) {
    throw InputError(what + ": unsupported mesh format '" + extension + "' (supported: " + kSupportedList + ")");
  }
  if (extension == ".stl") check_stl(path, size, what);
  detail::check_ply(path, size, what, extension == ".ply");
  if (extension == ".dae") check_collada(path, size, what);

#ifdef BATCHCOL_HAVE_ASSIMP
  Assimp::Importer importer;
  keep_only_supported_readers(importer);
  std::string bytes;
  try {
    bytes = read_bytes(path, size, what);
  } catch (const std::bad_alloc&) {
    throw InputError(what + ": the file (" + std::to_string(size) + " bytes) does not fit in memory");
  }
  if (bytes.find(kMemoryMeshName) != std::string::npos) {
    throw InputError(what + ": the file contains the reserved name " + kMemoryMeshName);
  }
  const std::string name = kMemoryMeshName + extension;
  importer.SetIOHandler(new MeshInMemory(name, bytes));  // the importer owns and deletes it
  // No post-processing: assimp's steps trust the face indices a broken file gives them (found by fuzzing). The node
  // transforms are applied below and duplicate points are removed before the hull.
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(name, 0);
  } catch (const std::exception& e) {  // e.g. std::bad_alloc on a header declaring billions of elements
    throw InputError(what + ": cannot read the mesh: " + e.what());
  }
  if (scene == nullptr) throw InputError(what + ": cannot read the mesh: " + importer.GetErrorString());
  return scene_points(*scene, what);
#else
  throw InputError(what + ": mesh support needs assimp (apt-get install libassimp-dev)");
#endif
}

}  // namespace batchcol
