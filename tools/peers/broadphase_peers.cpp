// Peer broad phases timed on our boxes (see broadphase_peers.hpp). Boxes become FCL boxes (identity rotation, so
// FCL's AABB is the box itself) and Bullet proxies with the default filter (every pair passes).
#include "peers/broadphase_peers.hpp"

#include <algorithm>
#include <chrono>
#include <functional>
#include <memory>
#include <string>

#ifdef BATCHCOL_HAVE_FCL
#include <fcl/broadphase/broadphase_SaP.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/narrowphase/collision_object.h>
#endif
#ifdef BATCHCOL_HAVE_BULLET
#include <btBulletCollisionCommon.h>
#endif

namespace batchcol::peers {
namespace {

// FCL's SaP setup grows much faster than n log n on these scenes (0.2 s at 10k, 28 s at 100k objects, measured with
// `batchcol stress --peers`): beyond this it is left out.
constexpr std::size_t kMaxFclSapObjects = 200000;

/// Median wall time of run(r) over `runs` runs; `before(r)`, when given, runs untimed before each run.
[[maybe_unused]] double median_ms(int runs, const std::function<void(int)>& run,
                                 const std::function<void(int)>& before = {}) {  // unused without FCL and Bullet
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    if (before) before(r);
    const auto start = std::chrono::steady_clock::now();
    run(r);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

#ifdef BATCHCOL_HAVE_FCL
bool count_pair(fcl::CollisionObjectd*, fcl::CollisionObjectd*, void* data) {
  ++*static_cast<std::size_t*>(data);
  return false;  // keep going: we want every pair
}

template <class Manager>
BroadphasePeerTiming time_fcl(const char* name, const std::vector<Aabb>& frame, const std::vector<Aabb>& moved,
                              int runs) {
  BroadphasePeerTiming t;
  t.name = name;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::CollisionObjectd*> raw;
  const auto place = [&](const std::vector<Aabb>& boxes) {
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      objects[i]->setTranslation(0.5 * (boxes[i].min + boxes[i].max));
      objects[i]->computeAABB();
    }
  };
  for (const Aabb& b : frame) {
    auto box = std::make_shared<fcl::Boxd>(b.max - b.min);
    objects.push_back(std::make_unique<fcl::CollisionObjectd>(box, fcl::Transform3d::Identity()));
    raw.push_back(objects.back().get());
  }
  std::unique_ptr<Manager> manager;
  t.rebuild_ms = median_ms(runs, [&](int) {
    place(frame);
    manager = std::make_unique<Manager>();
    manager->registerObjects(raw);
    manager->setup();
    t.rebuild_pairs = 0;
    manager->collide(&t.rebuild_pairs, count_pair);
  });
  t.update_ms = median_ms(runs, [&](int r) {
    place(r % 2 == 0 ? moved : frame);
    manager->update();
    t.update_pairs = 0;
    manager->collide(&t.update_pairs, count_pair);
  });
  if (runs % 2 == 0) {  // report the pairs of the moved frame
    place(moved);
    manager->update();
    t.update_pairs = 0;
    manager->collide(&t.update_pairs, count_pair);
  }
  return t;
}
#endif

#ifdef BATCHCOL_HAVE_BULLET
btVector3 bt(const Eigen::Vector3d& v) { return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z())); }

BroadphasePeerTiming time_bullet(const std::vector<Aabb>& frame, const std::vector<Aabb>& moved, int runs) {
  BroadphasePeerTiming t;
  t.name = "Bullet btDbvtBroadphase";
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher(&configuration);
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::vector<btBroadphaseProxy*> proxies(frame.size(), nullptr);
  // Bullet frees a proxy only through destroyProxy(), not in the broad phase's destructor (LeakSanitizer).
  const auto release = [&](int) {
    if (!broadphase) return;
    for (btBroadphaseProxy*& p : proxies) {
      if (p != nullptr) broadphase->destroyProxy(p, &dispatcher);
      p = nullptr;
    }
    broadphase.reset();
  };
  t.rebuild_ms = median_ms(runs, [&](int) {
    broadphase = std::make_unique<btDbvtBroadphase>();
    for (std::size_t i = 0; i < frame.size(); ++i)
      proxies[i] = broadphase->createProxy(bt(frame[i].min), bt(frame[i].max), BOX_SHAPE_PROXYTYPE, nullptr,
                                           btBroadphaseProxy::DefaultFilter, btBroadphaseProxy::AllFilter,
                                           &dispatcher);
    broadphase->calculateOverlappingPairs(&dispatcher);
    t.rebuild_pairs = static_cast<std::size_t>(broadphase->getOverlappingPairCache()->getNumOverlappingPairs());
  }, release);
  t.update_ms = median_ms(runs, [&](int r) {
    const std::vector<Aabb>& boxes = r % 2 == 0 ? moved : frame;
    for (std::size_t i = 0; i < boxes.size(); ++i)
      broadphase->setAabb(proxies[i], bt(boxes[i].min), bt(boxes[i].max), &dispatcher);
    broadphase->calculateOverlappingPairs(&dispatcher);
    t.update_pairs = static_cast<std::size_t>(broadphase->getOverlappingPairCache()->getNumOverlappingPairs());
  });
  release(0);
  return t;
}
#endif

}  // namespace

std::vector<BroadphasePeerTiming> time_broadphase_peers(const std::vector<Aabb>& frame, const std::vector<Aabb>& moved,
                                                        int runs, std::vector<std::string>& notes) {
  std::vector<BroadphasePeerTiming> out;
  runs = std::max(runs, 1);
#ifdef BATCHCOL_HAVE_BULLET
  out.push_back(time_bullet(frame, moved, runs));
#else
  notes.push_back("Bullet not found at configure time (install libbullet-dev)");
#endif
#ifdef BATCHCOL_HAVE_FCL
  out.push_back(time_fcl<fcl::DynamicAABBTreeCollisionManagerd>("FCL DynamicAABBTree", frame, moved, runs));
  if (frame.size() <= kMaxFclSapObjects) out.push_back(time_fcl<fcl::SaPCollisionManagerd>("FCL SaP", frame, moved, runs));
  else notes.push_back("FCL SaP skipped above " + std::to_string(kMaxFclSapObjects) + " objects (28 s per rebuild at 100k)");
#else
  // One note per peer that did not run (FCL gives two), so that peers run + notes = peers known.
  notes.push_back("FCL DynamicAABBTree: FCL not found at configure time (install libfcl-dev)");
  notes.push_back("FCL SaP: FCL not found at configure time (install libfcl-dev)");
#endif
  (void)frame, (void)moved;
  return out;
}

}  // namespace batchcol::peers
