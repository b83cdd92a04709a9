// Convex hulls through qhull's reentrant C library (Barber, Dobkin, Huhdanpaa, "The Quickhull algorithm for
// convex hulls", ACM TOMS 1996). Option Qt triangulates the facets so every face is a triangle.
#include "batchcol/shapes.hpp"
#include "convex_hull_search.hpp"

#include "batchcol/errors.hpp"

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unordered_map>

namespace batchcol {
namespace {

/// qhull writes its diagnostics to a FILE*; collect them in memory to put them in our error message.
class MemoryStream {
 public:
  MemoryStream() : file_(open_memstream(&buffer_, &size_)) {}
  ~MemoryStream() {
    if (file_) std::fclose(file_);
    std::free(buffer_);
  }
  MemoryStream(const MemoryStream&) = delete;
  MemoryStream& operator=(const MemoryStream&) = delete;
  FILE* file() const { return file_; }
  std::string text() {
    if (file_) std::fflush(file_);
    return buffer_ ? std::string(buffer_, size_) : std::string();
  }

 private:
  char* buffer_ = nullptr;
  std::size_t size_ = 0;
  FILE* file_;
};

std::string first_line(const std::string& s) {
  const auto start = s.find_first_not_of(" \n");
  if (start == std::string::npos) return "no message";
  return s.substr(start, s.find('\n', start) - start);
}

/// The direction at (a, b) of cube-map cell c (start_cell's layout), (a, b) in cell units: (0.5, 0.5) is the
/// centre, 0 and 1 the cell's edges.
Eigen::Vector3d cell_direction(std::uint32_t c, double a, double b) {
  const std::uint32_t face = c / (kHullStartGrid * kHullStartGrid), cu = c / kHullStartGrid % kHullStartGrid,
                      cv = c % kHullStartGrid;
  const int axis = static_cast<int>(face / 2);
  const double step = 2.0 / kHullStartGrid;
  Eigen::Vector3d d;
  d[axis] = face % 2 == 0 ? 1.0 : -1.0;
  d[(axis + 1) % 3] = -1.0 + (cu + a) * step;
  d[(axis + 2) % 3] = -1.0 + (cv + b) * step;
  return d;
}

/// Whether vertex v is the only maximiser of <p, d> for every direction d of cube-map cell c widened by 1/1000 of
/// a cell on each side (start_cell's rounding of d to a cell is far smaller), with a margin far above float
/// rounding: v beats each of its neighbours at the widened cell's four corners by 1e-5 (|v| + |n|) |d|. The cell
/// is the cone over its corners and the margin is linear in d, so it holds inside; beating its neighbours makes v
/// the global maximiser on a convex polytope (the climb's own argument). Needs the adjacency.
bool pure_cell(const ConvexHull& hull, std::uint32_t v, std::uint32_t c) {
  const Eigen::Vector3d& p = hull.vertices[v];
  if (hull.neighbor_offsets[v] == hull.neighbor_offsets[v + 1]) return false;  // on no face: nothing to compare
  for (const double a : {-1e-3, 1.0 + 1e-3})
    for (const double b : {-1e-3, 1.0 + 1e-3}) {
      const Eigen::Vector3d d = cell_direction(c, a, b);
      const double dn = d.norm();
      for (std::uint32_t k = hull.neighbor_offsets[v]; k < hull.neighbor_offsets[v + 1]; ++k) {
        const Eigen::Vector3d& n = hull.vertices[hull.neighbors[k]];
        if (!((p - n).dot(d) > 1e-5 * (p.norm() + n.norm()) * dn)) return false;
      }
    }
  return true;
}

/// ConvexHull::start_vertices: for each cube-map cell (kernels/support.hpp, start_cell), a vertex with the largest
/// dot product with the cell's centre direction, flagged kHullPureCell when pure_cell() holds. Found by steepest
/// ascent over the adjacency from the previous cell's vertex (a neighbouring direction): a few dozen dot products
/// a cell where a linear scan took one per vertex (6144 cells x 940 vertices). Needs the adjacency.
void build_start_vertices(ConvexHull& hull) {
  hull.start_vertices.assign(kHullStartCells, 0);
  std::uint32_t v = 0;  // the first vertex on a face (a hand-built hull may list one on none)
  while (v + 1 < hull.vertices.size() && hull.neighbor_offsets[v] == hull.neighbor_offsets[v + 1]) ++v;
  for (std::uint32_t c = 0; c < kHullStartCells; ++c) {
    const Eigen::Vector3d d = cell_direction(c, 0.5, 0.5);
    double best = hull.vertices[v].dot(d);
    for (std::uint32_t from = kNoHullVertex; from != v;) {  // on a convex polytope a local maximum is global
      from = v;
      for (std::uint32_t k = hull.neighbor_offsets[from]; k < hull.neighbor_offsets[from + 1]; ++k) {
        const double dk = hull.vertices[hull.neighbors[k]].dot(d);
        if (dk > best) best = dk, v = hull.neighbors[k];
      }
    }
    hull.start_vertices[c] = pure_cell(hull, v, c) ? v | kHullPureCell : v;
  }
}

/// ConvexHull::neighbor_block_*: the compressed adjacency rows cut into padded blocks with their coordinates.
void build_neighbor_blocks(ConvexHull& hull) {
  constexpr std::uint32_t B = ConvexHull::kNeighborBlock;
  hull.neighbor_block_offsets.assign(1, 0);
  hull.neighbor_block_index.clear();
  hull.neighbor_block_xyz.clear();
  for (std::size_t v = 0; v + 1 < hull.neighbor_offsets.size(); ++v) {
    const std::uint32_t first = hull.neighbor_offsets[v], last = hull.neighbor_offsets[v + 1];
    for (std::uint32_t k = first; k < last; k += B) {
      std::uint32_t index[B];
      for (std::uint32_t j = 0; j < B; ++j) index[j] = hull.neighbors[k + j < last ? k + j : first];
      for (std::uint32_t j = 0; j < B; ++j) hull.neighbor_block_index.push_back(index[j]);
      for (int c = 0; c < 3; ++c)
        for (std::uint32_t j = 0; j < B; ++j) hull.neighbor_block_xyz.push_back(hull.vertices[index[j]][c]);
    }
    hull.neighbor_block_offsets.push_back(static_cast<std::uint32_t>(hull.neighbor_block_index.size() / B));
  }
}

void build_adjacency(ConvexHull& hull) {
  std::vector<std::vector<std::uint32_t>> adj(hull.vertices.size());
  for (const auto& f : hull.faces)
    for (int e = 0; e < 3; ++e) {
      adj[f[e]].push_back(f[(e + 1) % 3]);
      adj[f[(e + 1) % 3]].push_back(f[e]);
    }
  hull.neighbor_offsets.assign(1, 0);
  for (auto& list : adj) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    hull.neighbors.insert(hull.neighbors.end(), list.begin(), list.end());
    hull.neighbor_offsets.push_back(static_cast<std::uint32_t>(hull.neighbors.size()));
  }
}

// Names the flat configuration qhull refused, for the error message only (qhull itself decides what is flat).
// Relative thresholds of 1e-12 of the point cloud's extent: far below any deliberate feature, far above rounding.
std::string describe_flat_points(const std::vector<Eigen::Vector3d>& points) {
  const Eigen::Vector3d& p0 = points.front();
  std::size_t far = 0;
  for (std::size_t i = 1; i < points.size(); ++i)
    if ((points[i] - p0).squaredNorm() > (points[far] - p0).squaredNorm()) far = i;
  const double extent = (points[far] - p0).norm();
  if (!(extent > 0.0)) return "all " + std::to_string(points.size()) + " points coincide";
  const Eigen::Vector3d axis = (points[far] - p0) / extent;
  std::size_t off = 0;
  double off_distance = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = (points[i] - p0).cross(axis).norm();
    if (d > off_distance) off_distance = d, off = i;
  }
  if (off_distance <= 1e-12 * extent) return "all " + std::to_string(points.size()) + " points are collinear";
  const Eigen::Vector3d normal = axis.cross(points[off] - p0).normalized();
  double height = 0.0;
  for (const auto& p : points) height = std::max(height, std::abs((p - p0).dot(normal)));
  if (height <= 1e-12 * extent) return "all " + std::to_string(points.size()) + " points are coplanar";
  return "the points are nearly coplanar";
}

}  // namespace

std::shared_ptr<const ConvexHull> with_search_structures(std::shared_ptr<const ConvexHull> hull) {
  const std::size_t nv = hull->vertices.size();
  for (const auto& f : hull->faces)
    for (const std::uint32_t i : f)
      if (i >= nv) throw InputError("hull faces: vertex index " + std::to_string(i) + " of " + std::to_string(nv) + " vertices");
  // The adjacency the supports climb on must be the faces' (a wrong edge makes hill climbing stop at a vertex that
  // is not the maximiser): derived from them here, and a given one must be the same.
  ConvexHull derived;
  derived.faces = hull->faces;
  derived.vertices.resize(nv);
  build_adjacency(derived);
  const bool has_adjacency = !hull->neighbor_offsets.empty() || !hull->neighbors.empty();
  if (has_adjacency && (hull->neighbor_offsets != derived.neighbor_offsets || hull->neighbors != derived.neighbors))
    throw InputError("hull neighbors: the vertex adjacency does not match the faces' edges");
  bool complete = has_adjacency && hull->start_vertices.size() == kHullStartCells;
  // Any vertex starts a climb, but a kHullPureCell flag skips it: a flagged cell must pass pure_cell() (the
  // neighbour checks only, ~100 us for 1536 cells, not the table's linear scans).
  for (std::uint32_t c = 0; complete && c < kHullStartCells; ++c) {
    const std::uint32_t v = hull->start_vertices[c] & ~kHullPureCell;
    complete = v < nv && (!(hull->start_vertices[c] & kHullPureCell) || pure_cell(*hull, v, c));
  }
  if (complete) {  // the blocks must be the adjacency's, in build_neighbor_blocks' layout
    ConvexHull blocks;
    blocks.vertices = hull->vertices;
    blocks.neighbor_offsets = hull->neighbor_offsets;
    blocks.neighbors = hull->neighbors;
    build_neighbor_blocks(blocks);
    complete = blocks.neighbor_block_offsets == hull->neighbor_block_offsets &&
               blocks.neighbor_block_index == hull->neighbor_block_index &&
               blocks.neighbor_block_xyz == hull->neighbor_block_xyz;
  }
  if (complete) return hull;
  auto full = std::make_shared<ConvexHull>(*hull);
  full->neighbor_offsets = std::move(derived.neighbor_offsets);
  full->neighbors = std::move(derived.neighbors);
  build_neighbor_blocks(*full);
  build_start_vertices(*full);
  return full;
}

std::shared_ptr<const ConvexHull> compute_convex_hull(const std::vector<Eigen::Vector3d>& points,
                                                      const std::string& what) {
  if (points.size() < 4)
    throw InputError(what + ": fewer than 4 non-coplanar points, no 3D convex hull: only " +
                     std::to_string(points.size()) + " points");
  std::vector<coordT> coords;
  coords.reserve(points.size() * 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) throw InputError(what + ": point " + std::to_string(i) + " is not finite");
    // Beyond the input limits qhull's own arithmetic overflows and calls valid tetrahedra "collinear".
    if (points[i].cwiseAbs().maxCoeff() > kMaxLength) {
      throw InputError(what + ": point " + std::to_string(i) + " has a coordinate beyond the input limit of 1e50 m");
    }
    coords.insert(coords.end(), {points[i].x(), points[i].y(), points[i].z()});
  }

  qhT qh_storage;
  qhT* qh = &qh_storage;
  MemoryStream err;
  qh_zero(qh, err.file());
  char options[] = "qhull Qt";
  const int exit_code = qh_new_qhull(qh, 3, static_cast<int>(points.size()), coords.data(), False, options, nullptr,
                                     err.file());
  auto hull = std::make_shared<ConvexHull>();
  if (exit_code == 0) {
    std::unordered_map<int, std::uint32_t> index;  // qhull point id -> hull vertex index
    vertexT* vertex;
    FORALLvertices {
      index[qh_pointid(qh, vertex->point)] = static_cast<std::uint32_t>(hull->vertices.size());
      hull->vertices.push_back(points[static_cast<std::size_t>(qh_pointid(qh, vertex->point))]);
    }
    facetT* facet;
    FORALLfacets {
      std::array<std::uint32_t, 3> f{};
      int k = 0;
      vertexT** vertexp;
      FOREACHvertex_(facet->vertices) {
        if (k < 3) f[k] = index[qh_pointid(qh, vertex->point)];
        ++k;
      }
      if (k != 3) continue;  // cannot happen with Qt; skip rather than read garbage
      const Eigen::Vector3d n(facet->normal[0], facet->normal[1], facet->normal[2]);
      const auto& v = hull->vertices;
      if ((v[f[1]] - v[f[0]]).cross(v[f[2]] - v[f[0]]).dot(n) < 0.0) std::swap(f[1], f[2]);
      hull->faces.push_back(f);
      hull->face_normals.push_back(n.normalized());
    }
  }
  const std::string message = err.text();
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (exit_code != 0)
    throw InputError(what + ": fewer than 4 non-coplanar points, no 3D convex hull: " + describe_flat_points(points) +
                     " (qhull: " + first_line(message) + ")");
  if (hull->vertices.size() < 4 || hull->faces.size() < 4)
    throw InputError(what + ": the convex hull is degenerate (fewer than 4 vertices)");
  for (const auto& v : hull->vertices) hull->centroid += v;
  hull->centroid /= static_cast<double>(hull->vertices.size());
  for (const auto& v : hull->vertices) hull->radius = std::max(hull->radius, v.norm());
  build_adjacency(*hull);
  build_neighbor_blocks(*hull);
  build_start_vertices(*hull);
  return hull;
}

}  // namespace batchcol
