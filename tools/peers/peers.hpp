// Which peer libraries (FCL, Bullet, Coal) this build found at configure time. The adapters themselves
// (peers/fcl_adapter.hpp, peers/bullet_adapter.hpp, peers/coal_adapter.hpp) are compiled only when their library
// was found.
#pragma once

namespace batchcol::peers {

bool have_fcl();
bool have_bullet();
bool have_coal();

}  // namespace batchcol::peers
