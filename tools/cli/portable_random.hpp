// The CLI's name for the testkit's portable random source (tools/testkit/portable_random.hpp), kept so that the
// command files that draw from it need no edit when the generator moves.
#pragma once

#include "testkit/portable_random.hpp"

namespace batchcol::cli {

using testkit::PortableRandom;

}  // namespace batchcol::cli
