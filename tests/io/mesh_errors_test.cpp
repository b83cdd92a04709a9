// Every kind of broken mesh file gives one InputError naming the file and the problem, through the C++ loader
// (load_mesh_points + compute_convex_hull) and through `batchcol query` on a batch file that references the mesh:
// exit code 2, one `batchcol: error:` line naming the file, nothing on stdout and no output file written.
#include "batchcol/io.hpp"
#include "tools/cli_runner.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include <sys/stat.h>
#include <unistd.h>

namespace batchcol {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const std::string kDataDir = BATCHCOL_TEST_DATA_DIR;

std::string cube_stl() { return testing::read_text(fs::path(kDataDir) / "cube.bin.stl"); }

void set_u32(std::string& bytes, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>((v >> (8 * i)) & 0xFF);
}

class BrokenMesh : public testing::CliTest {
 protected:
  // Loads `mesh` as a hull through the C++ API and through the CLI; both must fail naming the file and `problem`.
  void expect_rejected(const fs::path& mesh, const std::string& problem) {
    const std::string path = mesh.string();
    std::string message;
    try {
      compute_convex_hull(load_mesh_points(path), "mesh '" + path + "'");
      ADD_FAILURE() << "the C++ loader accepted " << path;
    } catch (const InputError& e) {
      message = e.what();
    }
    EXPECT_THAT(message, HasSubstr("mesh '" + path + "'"));
    EXPECT_THAT(message, HasSubstr(problem));

    // The batch file lives in its own folder; the mesh is referenced by an absolute path.
    fs::create_directories(dir_ / "batch");
    testing::write_text(dir_ / "batch" / "b.json",
                        R"({"shapes":[{"type":"sphere","radius":1},{"type":"mesh","file":")" + path +
                            R"("}],"pairs":[{"a":0,"b":1}]})");
    const fs::path out = dir_ / "batch" / "out.csv";
    const testing::RunResult r = run("query '" + (dir_ / "batch" / "b.json").string() + "' --out '" + out.string() + "'");
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_THAT(r.err, StartsWith("batchcol: error: "));
    EXPECT_THAT(r.err, HasSubstr("/shapes/1/file"));
    EXPECT_THAT(r.err, HasSubstr("mesh '" + path + "'"));
    EXPECT_THAT(r.err, HasSubstr(problem));
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;  // one message
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_ / "batch"), fs::directory_iterator()), 1)
        << "a temporary or partial output was left behind";
  }

  fs::path write(const std::string& name, const std::string& bytes) {
    testing::write_text(dir_ / name, bytes);
    return dir_ / name;
  }
};

TEST_F(BrokenMesh, TruncatedBinaryStl) {
  expect_rejected(write("cut.stl", cube_stl().substr(0, 400)), "truncated");
  expect_rejected(write("cut_header.stl", cube_stl().substr(0, 50)), "shorter than the 84-byte header");
}

TEST_F(BrokenMesh, WrongTriangleCountInBinaryStlHeader) {
  std::string more = cube_stl(), fewer = cube_stl();
  set_u32(more, 80, 15);   // the file holds 12
  set_u32(fewer, 80, 9);
  expect_rejected(write("more.stl", more), "the header declares 15 triangles (84 + 50 x 15 = 834 bytes) but the file has 684 bytes");
  expect_rejected(write("fewer.stl", fewer), "triangle count is wrong");
  std::string huge = cube_stl();
  set_u32(huge, 80, 0xFFFFFFFFu);  // 84 + 50 * (2^32 - 1) must not overflow into a match
  expect_rejected(write("huge.stl", huge), "declares 4294967295 triangles");
}

TEST_F(BrokenMesh, NanCoordinates) {
  std::string binary = cube_stl();
  binary.replace(84 + 12 + 4, 4, std::string("\x00\x00\xc0\x7f", 4));  // y of triangle 0's first vertex = NaN
  expect_rejected(write("nan.stl", binary), "triangle 0 has a non-finite coordinate");
  expect_rejected(write("nan_ascii.stl",
                        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\n"
                        "endfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\n"
                        "endfacet\nendsolid t\n"),
                  "is not finite");
  expect_rejected(write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 nan\nf 1 2 3\nf 1 2 4\n"), "is not finite");
  expect_rejected(write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e999\nf 1 2 3\nf 1 2 4\n"), "is not finite");
}

TEST_F(BrokenMesh, EmptyFile) {
  for (const char* name : {"empty.stl", "empty.obj", "empty.ply", "empty.dae"})
    expect_rejected(write(name, ""), "the file is empty (0 bytes)");
}

TEST_F(BrokenMesh, ZeroFaces) {
  expect_rejected(write("zero.stl", cube_stl().substr(0, 80) + std::string(4, '\0')), "zero triangles");
  expect_rejected(write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"), "4 vertices but zero faces");
  expect_rejected(write("points.ply",
                        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                        "element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"),
                  "zero faces");
}

TEST_F(BrokenMesh, FewerThanFourNonCoplanarPoints) {
  const std::string problem = "fewer than 4 non-coplanar points";
  // A flat square of two triangles, plus a fifth point in its plane.
  const fs::path coplanar = write("coplanar.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 2 0\nf 1 2 3\nf 1 3 4\nf 3 4 5\n");
  expect_rejected(coplanar, problem);
  expect_rejected(coplanar, "all 5 points are coplanar");
  const fs::path collinear = write("collinear.obj", "v 0 0 0\nv 1 1 1\nv 2 2 2\nv 3 3 3\nf 1 2 3\nf 2 3 4\n");
  expect_rejected(collinear, "all 4 points are collinear");
  // One triangle only: three points.
  expect_rejected(write("triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), "only 3 points");
  // Four copies of one point: assimp joins identical vertices, what is left is one point.
  const fs::path same = write("same.obj", "v 1 2 3\nv 1 2 3\nv 1 2 3\nv 1 2 3\nf 1 2 3\nf 2 3 4\n");
  expect_rejected(same, problem);
}

// Found by tools/fuzz (fuzz_mesh_file): assimp's PLY reader loops forever on a header without end_header or with
// a line it does not know, and writes past a heap buffer when an element is declared twice
// (tools/fuzz/known/assimp_ply_heap_overflow.ply). The header grammar is checked before assimp sees the file.
TEST_F(BrokenMesh, PlyHeaderIsCheckedBeforeAssimpReadsIt) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
  expect_rejected(write("no_end.ply", header), "PLY header has no end_header line");
  expect_rejected(write("fuzzed.ply", "ply\nformat ascii 1.0\nelement vertex 6\nproperty fl0 0\n-0.5 0 0\n0 0.5 0\n"),
                  "PLY header line 4: expected 'property TYPE NAME' or 'property list TYPE TYPE NAME' after an element");
  expect_rejected(write("junk.ply", header + "foo bar\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"),
                  "PLY header line 7: unknown keyword 'foo'");
  expect_rejected(write("data_before_end.ply", header + "0 0 0\n1 0 0\n"), "PLY header line 7: unknown keyword '0'");
  // Assimp reads any capitalisation of the magic: "pLy" must be checked too (it hung assimp, tools/fuzz/known).
  expect_rejected(write("mixed_case.ply", "pLy\nformat ascii 1.0\nend_header\n"), "PLY header line 1: expected 'ply' alone");
  expect_rejected(write("magic_junk.ply", "PLYX\nformat ascii 1.0\nend_header\n"), "PLY header line 1: expected 'ply' alone");
  expect_rejected(write("two_formats.ply", "ply\nformat binary_little_endian 1.0\nformat ascii 1.0\nend_header\n"),
                  "PLY header line 3: expected one 'format ascii|binary_little_endian|binary_big_endian 1.0' line");
  std::string twice = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                      "property float z\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  twice += std::string(12 * 4 * 4, '\0');
  expect_rejected(write("twice.ply", twice), "PLY header line 7: element 'vertex' declared twice");
  // The valid binary PLY of the same shape still loads.
  std::string once = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                     "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";
  const float corners[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  once.append(reinterpret_cast<const char*>(corners), sizeof corners);
  const std::int32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (const auto& f : faces) {
    once += '\x03';
    once.append(reinterpret_cast<const char*>(f), sizeof f);
  }
  EXPECT_EQ(load_mesh_points(write("once.ply", once).string()).size(), 4u);
}

// Found by tools/fuzz (fuzz_mesh_file): assimp's OFF reader crashed (SEGV) on this file, an OFF header whose face
// list runs into a binary PLY. Only the readers of the supported formats are registered now: under any name the
// file is refused with a message, never read by the OFF reader.
TEST_F(BrokenMesh, FuzzedOffFileIsRefusedUnderEveryName) {
  const std::string off = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 \x02ply\nformat binary_little_endian 1.0\n"
                          "element vertex 4\nproperty float 3\nx\nproperty float y\nproperty float z\nelement face 4\n"
                          "property list uchar int vertex_indices\nend_header\n" +
                          std::string(14, '\0') + "\x80\x3f" + std::string(14, '\0') + "\x80\x3f" +
                          std::string(14, '\0') + "\x80\x3f\x03";
  expect_rejected(write("fuzzed.off", off), "unsupported mesh format '.off' (supported: .obj, .stl, .ply, .dae)");
  for (const char* name : {"fuzzed.obj", "fuzzed.ply", "fuzzed.dae", "fuzzed.stl", "fuzzed.OBJ"})
    expect_rejected(write(name, off), "");  // any one clear message naming the file
}

TEST_F(BrokenMesh, DirectoryInsteadOfFile) {
  fs::create_directories(dir_ / "folder.stl");
  expect_rejected(dir_ / "folder.stl", "is a directory");
}

TEST_F(BrokenMesh, MissingFile) { expect_rejected(dir_ / "absent.obj", "no such file"); }

TEST_F(BrokenMesh, UnreadablePermission) {
  if (::geteuid() == 0) GTEST_SKIP() << "root reads files whatever their mode; see ParentIsNotADirectory and Fifo";
  const fs::path mesh = write("secret.stl", cube_stl());
  ASSERT_EQ(::chmod(mesh.c_str(), 0), 0);
  expect_rejected(mesh, "cannot open the file for reading: Permission denied");
  ::chmod(mesh.c_str(), 0644);
}

// Unreadable even for root: a path through a regular file, a FIFO (opening it would block), a symlink loop.
TEST_F(BrokenMesh, ParentIsNotADirectory) {
  const fs::path file = write("plain.obj", "v 0 0 0\n");
  expect_rejected(file / "mesh.stl", "cannot access the file: Not a directory");
}

TEST_F(BrokenMesh, FifoIsNotARegularFile) {
  const fs::path fifo = dir_ / "pipe.stl";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  expect_rejected(fifo, "not a regular file");
}

TEST_F(BrokenMesh, SymlinkLoop) {
  fs::create_symlink(dir_ / "loop_b.stl", dir_ / "loop_a.stl");
  fs::create_symlink(dir_ / "loop_a.stl", dir_ / "loop_b.stl");
  expect_rejected(dir_ / "loop_a.stl", "cannot access the file: Too many levels of symbolic links");
}

// Found by tools/fuzz (fuzz_mesh_file): assimp 5.2.5's COLLADA reader trusts the numbers a file declares. A quote
// inside <p> made it append indices until ~19 GB were allocated (tools/fuzz/known/assimp_dae_huge_allocation.dae);
// huge counts are reserved as is (bad_alloc), a huge stride crashed it (SEGV). Each variant below of the valid box
// was checked against assimp directly; the loader now refuses them before assimp reads the file.
TEST_F(BrokenMesh, ColladaNumbersAreCheckedAgainstTheFileSizeBeforeAssimpReadsThem) {
  const std::string box = testing::read_text(fs::path(kDataDir) / "box_translated.dae");
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string s = box;
    const std::size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return at == std::string::npos ? s : s.replace(at, from.size(), to);
  };
  expect_rejected(write("quote.dae", with("7 2 7 6", "7\"2 7 6")), "COLLADA line 27: <p> entry '7\"2' is not an unsigned integer");
  expect_rejected(write("comma.dae", with("7 2 7 6", "7,2 7 6")), "<p> entry '7,2' is not an unsigned integer");
  expect_rejected(write("negative.dae", with("<p>0 2", "<p>-1 2")), "<p> entry '-1' is not an unsigned integer");
  const std::string array_count = with("count=\"24\"", "count=\"3000000000\"");
  expect_rejected(write("array_count.dae", array_count), "COLLADA line 13: <float_array> count 3000000000 is more than this " +
                                                             std::to_string(array_count.size()) + "-byte file can hold");
  expect_rejected(write("triangles.dae", with("triangles count=\"12\"", "triangles count=\"2000000000\"")),
                  "<triangles> count 2000000000 is more than");
  expect_rejected(write("stride.dae", with("stride=\"3\"", "stride=\"300000000\"")), "<accessor> stride 300000000 is more than");
  expect_rejected(write("offset.dae", with("offset=\"0\"", "offset=\"400000000\"")), "<input> offset 400000000 is more than");
  expect_rejected(write("accessor.dae", with("count=\"8\" stride=\"3\"", "count=\"400\" stride=\"3\"")),
                  "<accessor> count x stride = 400 x 3 values, more than this file can hold");
  expect_rejected(write("quoted.dae", with("count=\"24\"", "count = '3000000000'")), "<float_array> count 3000000000");
  expect_rejected(write("not_a_number.dae", with("count=\"24\"", "count=\"24x\"")), "<float_array> count '24x' is not an unsigned integer");
  // Polygons: a vcount entry is a polygon's vertex count (assimp reserved 3e8 of them).
  std::string polylist = with("<triangles count=\"12\">", "<polylist count=\"12\">");
  polylist.replace(polylist.find("</triangles>"), 12, "</polylist>");
  polylist.replace(polylist.find("<p>"), 3, "<vcount>3 3 3 3 3 3 3 3 3 3 3 3</vcount>\n          <p>");
  EXPECT_EQ(load_mesh_points(write("polylist.dae", polylist).string()).size(), 8u);
  std::string huge_vcount = polylist;
  huge_vcount.replace(huge_vcount.find("<vcount>3"), 9, "<vcount>300000000");
  expect_rejected(write("vcount.dae", huge_vcount), "<vcount> entry 300000000 is more than");
  std::string vcount_sum = polylist;
  vcount_sum.replace(vcount_sum.find("<vcount>3 3 3"), 13, "<vcount>800 800 800");
  expect_rejected(write("vcount_sum.dae", vcount_sum), "<vcount> sums to 2427 vertices, more than this file can hold");
  // Still accepted: the box itself, and markup-like text inside a comment.
  EXPECT_EQ(load_mesh_points(write("box.dae", box).string()).size(), 8u);
  const std::string commented = with("<library_geometries>", "<!-- <p>1 x</p> count=\"-1\" -->\n  <library_geometries>");
  EXPECT_EQ(load_mesh_points(write("comment.dae", commented).string()).size(), 8u);
}

// A malformed ASCII STL facet (two vertices) is assimp's to refuse. Its reader then leaks an aiMesh and an aiNode
// (assimp 5.2.5, not our code): the ASan test build suppresses leaks inside libassimp only
// (tools/fuzz/lsan_assimp.supp), so this test also shows that our side of the loader leaks nothing.
TEST_F(BrokenMesh, MalformedAsciiStlFacet) {
  expect_rejected(write("two_vertices.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                            "endloop\nendfacet\nendsolid t\n"),
                  "cannot read the mesh");
}

// Every input in tools/fuzz/known/ (assimp bugs found by fuzzing: a hang, a heap overflow, a 19 GB allocation) is
// refused with one message naming the file, before assimp reads it. Under ASan this also proves no invalid access.
TEST_F(BrokenMesh, EveryKnownFuzzerFindingIsRefused) {
  const fs::path known = fs::path(kDataDir) / ".." / ".." / "tools" / "fuzz" / "known";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(known)) {
    SCOPED_TRACE(entry.path().string());
    expect_rejected(entry.path(), "");  // a clear message naming the file (the exact text is in the tests above)
    ++files;
  }
  EXPECT_GE(files, 3);
}

}  // namespace
}  // namespace batchcol
