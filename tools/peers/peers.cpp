#include "peers/peers.hpp"

namespace batchcol::peers {

#ifdef BATCHCOL_HAVE_FCL
bool have_fcl() { return true; }
#else
bool have_fcl() { return false; }
#endif

#ifdef BATCHCOL_HAVE_BULLET
bool have_bullet() { return true; }
#else
bool have_bullet() { return false; }
#endif

#ifdef BATCHCOL_HAVE_COAL
bool have_coal() { return true; }
#else
bool have_coal() { return false; }
#endif

}  // namespace batchcol::peers

#ifndef BATCHCOL_HAVE_EMBREE
#include "peers/embree_rays.hpp"
namespace batchcol::peers {
bool have_embree() { return false; }  // the EmbreeRayScene class is only compiled with Embree
}  // namespace batchcol::peers
#endif
