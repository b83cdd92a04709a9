// Convex hulls through qhull's reentrant C library (Barber, Dobkin, Huhdanpaa, "The Quickhull algorithm for
// convex hulls", ACM TOMS 1996). Option Qt triangulates the facets so every face is a triangle.
#include "batchcol/shapes.hpp"
#include "convex_hull_search.hpp"

#include "batchcol/errors.hpp"
#include "kernels/support.hpp"  // kHillClimbMinVertices

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <algorithm>
#include <cmath>
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

/// Whether vertex u can be a support vertex of some direction of cube-map cell c widened by 1/1000 of a cell on
/// each side (pure_cell()'s widening), with margin `margin` (per unit |d|): whether some d of the widened cell
/// has <u - n, d> >= -margin |d| for every neighbour n of u. Conservative (true when unsure): |d| is bounded by
/// its largest value on the widened cell, `dmax`, which makes every constraint linear in the cell coordinates
/// (a, b) of d = d0 + a da + b db (cell_direction(c, a, b)); the widened square is clipped by the half-planes,
/// and u passes if something is left (points within 1e-12 of a line kept: the margin is far above that).
/// Neighbours n with first[n] == c are taken first (the vertices already found for cell c: the likeliest to beat u
/// over the whole cell, which rejects u at once); `first` may be null.
bool near_support_in_cell(const ConvexHull& hull, std::uint32_t u, const Eigen::Vector3d& d0, const Eigen::Vector3d& da,
                          const Eigen::Vector3d& db, double margin, double dmax, const std::uint32_t* first,
                          std::uint32_t c) {
  if (hull.neighbor_offsets[u] == hull.neighbor_offsets[u + 1]) return false;  // on no face: no support vertex
  // Neighbour n's constraint g(a, b) = <u - n, d0 + a da + b db> + margin dmax >= -tol, one text for the quick
  // rejection and the clipping (tol: points within 1e-12 of the line count as on it).
  struct Line {
    double g0, ga, gb, tol;
    double at(double a, double b) const { return g0 + ga * a + gb * b; }
  };
  const auto line = [&](std::uint32_t n) {
    const Eigen::Vector3d e = hull.vertices[u] - hull.vertices[n];
    Line l{e.dot(d0) + margin * dmax, e.dot(da), e.dot(db), 0.0};
    l.tol = 1e-12 * (std::abs(l.g0) + std::abs(l.ga) + std::abs(l.gb));
    return l;
  };
  const double lo = -1e-3, hi = 1.0 + 1e-3;  // the widened cell
  if (first != nullptr) {  // the quick rejection: a found neighbour beats u at the widened cell's four corners
    for (std::uint32_t k = hull.neighbor_offsets[u]; k < hull.neighbor_offsets[u + 1]; ++k) {
      if (first[hull.neighbors[k]] != c) continue;
      const Line l = line(hull.neighbors[k]);
      if (l.at(lo, lo) < -l.tol && l.at(hi, lo) < -l.tol && l.at(hi, hi) < -l.tol && l.at(lo, hi) < -l.tol)
        return false;
    }
  }
  constexpr int kMax = 32;  // a convex polygon clipped by lines: 4 + one vertex per line at most (the valence)
  double poly[kMax][2], next[kMax][2];
  int count = 4;
  const double square[4][2] = {{lo, lo}, {hi, lo}, {hi, hi}, {lo, hi}};
  for (int i = 0; i < 4; ++i) poly[i][0] = square[i][0], poly[i][1] = square[i][1];
  for (std::uint32_t k = hull.neighbor_offsets[u]; k < hull.neighbor_offsets[u + 1] && count > 0; ++k) {
    const Line l = line(hull.neighbors[k]);
    double g[kMax];
    int inside = 0;
    for (int i = 0; i < count; ++i) inside += (g[i] = l.at(poly[i][0], poly[i][1])) >= -l.tol;
    if (inside == count) continue;  // the line misses the polygon: nothing clipped (the common case)
    if (inside == 0) return false;
    if (count + 1 >= kMax) return true;  // (cannot happen; unsure = true)
    int out = 0;
    for (int i = 0; i < count; ++i) {
      const int j = (i + 1) % count;
      if (g[i] >= -l.tol) next[out][0] = poly[i][0], next[out][1] = poly[i][1], ++out;
      if ((g[i] >= -l.tol) != (g[j] >= -l.tol)) {  // the edge crosses the line: its crossing point
        const double t = g[i] / (g[i] - g[j]);
        next[out][0] = poly[i][0] + t * (poly[j][0] - poly[i][0]);
        next[out][1] = poly[i][1] + t * (poly[j][1] - poly[i][1]);
        ++out;
      }
    }
    count = out;
    for (int i = 0; i < count; ++i) poly[i][0] = next[i][0], poly[i][1] = next[i][1];
  }
  return count > 0;
}

/// ConvexHull::cell_candidates and vertex_floats (needs start_vertices and the adjacency; none for hulls the kernels
/// scan). A pure
/// cell's entry is its vertex. For a cell that is not pure, the vertices that pass near_support_in_cell() with
/// margin 2e-5 R (R the largest vertex norm), found by a search over the adjacency from the cell centre's
/// maximiser that expands from every passing vertex: one is the entry, 2 to kHullCellCandidatesMax are a list in
/// ascending index order, more leave the cell without an entry (its supports climb).
///
/// Why the first maximum over the list is the linear scan's vertex, bit for bit, in double and in float: let d be
/// a direction whose start_cell() is c (so d is inside c widened by 1/1000 of a cell: the cell arithmetic's
/// rounding is ~1e-5 cell), and w a vertex whose rounded dot product (hull_dot, in T) equals the largest rounded
/// one. Then for every vertex v, exactly, <w, d> >= <v, d> - 2 err with err <= ~5 2^-24 R |d| (coordinates rounded
/// to T, three products and two sums in T): w is within 1e-6 R |d| of the largest exact dot product, so below
/// every neighbour by at most the margin: w passes the test. The set G of vertices within the margin of the
/// maximum for some d of the cell is connected through hull edges (from any vertex an increasing edge path leads
/// to the maximiser of d, and every vertex on it is in G; the maximisers of the cell's directions are themselves
/// adjacent), it contains the centre's maximiser, and every vertex of G passes the test: the search finds all of G.
/// So every vertex with the largest rounded dot product is on the list, and the list's first maximum in
/// ascending index order is the scan's first maximum. (Vertices on no face are skipped, as the climb skips them.)
///
/// For directions so small that hull_dot's products are subnormal (|d| near the smallest cell-bearing direction,
/// ~1e-37 in float) the rounding bound above does not hold; the same is true of the pure cells. The wide GJK and
/// the reference compute the same vertex there all the same (one text).
///
/// Measured on the bench's hulls (points on ellipsoids, 20 hulls each): convex250 3580 pure cells, 2564 lists of
/// 2.29 vertices on average (at most 8), none left to climb; convex940 2019 pure, 4122 lists of 2.67 (14 longer
/// than 10), 4 cells climb. kHullCellCandidatesMax = 15 (what 4 bits hold) therefore leaves almost nothing to the
/// climb. The table is 47 KB (convex250) / 67 KB (convex940) per hull, next to ~24 KB for start_vertices; it
/// costs 13 M / 25 M instructions per hull to build (+68% / +73% of Shape::convex from points, callgrind).
void build_cell_candidates(ConvexHull& hull) {
  const std::size_t nv = hull.vertices.size();
  double radius = 0.0;
  for (const auto& v : hull.vertices) radius = std::max(radius, v.norm());
  const double margin = 2e-5 * radius;
  // Small hulls are scanned (kernels::kHillClimbMinVertices), and an entry holds a vertex index in 28 bits.
  hull.cell_candidates.clear();
  hull.vertex_floats.clear();
  if (nv < kernels::kHillClimbMinVertices || nv >= (std::size_t(1) << 28)) return;
  hull.vertex_floats.reserve(3 * nv);
  for (const auto& v : hull.vertices)
    for (int k = 0; k < 3; ++k) hull.vertex_floats.push_back(static_cast<float>(v[k]));
  hull.cell_candidates.assign(kHullStartCells, 0);
  std::vector<std::uint32_t> mark(nv, kNoHullVertex), passed(nv, kNoHullVertex), stack, found;
  for (std::uint32_t c = 0; c < kHullStartCells; ++c) {
    if (hull.start_vertices[c] & kHullPureCell) {  // the vertex itself, no list
      hull.cell_candidates[c] = (hull.start_vertices[c] & ~kHullPureCell) << 4 | 1u;
      continue;
    }
    const Eigen::Vector3d d0 = cell_direction(c, 0.0, 0.0), da = cell_direction(c, 1.0, 0.0) - d0,
                          db = cell_direction(c, 0.0, 1.0) - d0;
    double dmax = 0.0;
    for (const double a : {-1e-3, 1.0 + 1e-3})
      for (const double b : {-1e-3, 1.0 + 1e-3}) dmax = std::max(dmax, cell_direction(c, a, b).norm());
    // The seed: the centre direction's maximiser, climbed to from the table's vertex (a table given with the hull
    // may name any vertex in a cell that is not pure; the argument below needs the seed in G).
    const Eigen::Vector3d centre = cell_direction(c, 0.5, 0.5);
    std::uint32_t seed = hull.start_vertices[c];
    if (seed >= nv) continue;
    double best = hull.vertices[seed].dot(centre);
    for (std::uint32_t from = kNoHullVertex; from != seed;) {
      from = seed;
      for (std::uint32_t k = hull.neighbor_offsets[from]; k < hull.neighbor_offsets[from + 1]; ++k) {
        const double dk = hull.vertices[hull.neighbors[k]].dot(centre);
        if (dk > best) best = dk, seed = hull.neighbors[k];
      }
    }
    stack.assign(1, seed);
    mark[seed] = c;
    found.clear();
    bool too_many = false;
    while (!stack.empty() && !too_many) {
      const std::uint32_t u = stack.back();
      stack.pop_back();
      // The seed is expanded even if it failed (it cannot, up to rounding: it is the centre's maximiser).
      const bool pass = near_support_in_cell(hull, u, d0, da, db, margin, dmax, passed.data(), c);
      if (pass) found.push_back(u), passed[u] = c;
      if (!pass && u != seed) continue;
      too_many = found.size() > kHullCellCandidatesMax;
      for (std::uint32_t k = hull.neighbor_offsets[u]; k < hull.neighbor_offsets[u + 1]; ++k) {
        const std::uint32_t n = hull.neighbors[k];
        if (mark[n] != c) mark[n] = c, stack.push_back(n);
      }
    }
    if (too_many || found.empty()) continue;
    if (found.size() == 1) {  // a cell pure_cell() did not flag, but the search finds one vertex: no list either
      hull.cell_candidates[c] = found[0] << 4 | 1u;
      continue;
    }
    std::sort(found.begin(), found.end());
    const std::uint32_t start = static_cast<std::uint32_t>(hull.cell_candidates.size());
    hull.cell_candidates[c] = start << 4 | static_cast<std::uint32_t>(found.size());
    hull.cell_candidates.insert(hull.cell_candidates.end(), found.begin(), found.end());
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
  if (complete) {
    // The candidate lists must be the ones built here (a missing vertex would give a wrong support): built once,
    // the hull is shared when it has them, else a copy gets them (compute_convex_hull() leaves them to this step).
    ConvexHull lists;
    lists.vertices = hull->vertices;
    lists.neighbor_offsets = hull->neighbor_offsets;
    lists.neighbors = hull->neighbors;
    lists.start_vertices = hull->start_vertices;
    build_cell_candidates(lists);
    if (lists.cell_candidates == hull->cell_candidates && lists.vertex_floats == hull->vertex_floats) return hull;
    auto with_lists = std::make_shared<ConvexHull>(*hull);
    with_lists->cell_candidates = std::move(lists.cell_candidates);
    with_lists->vertex_floats = std::move(lists.vertex_floats);
    return with_lists;
  }
  auto full = std::make_shared<ConvexHull>(*hull);
  full->neighbor_offsets = std::move(derived.neighbor_offsets);
  full->neighbors = std::move(derived.neighbors);
  build_neighbor_blocks(*full);
  build_start_vertices(*full);
  build_cell_candidates(*full);
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
  return hull;  // (the candidate lists: with_search_structures(), which Shape::convex calls, builds them once)
}

}  // namespace batchcol
