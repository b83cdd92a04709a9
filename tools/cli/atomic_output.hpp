// Writes an output file so that a failure never leaves it half-written or clobbers an existing one.
#pragma once

#include <functional>
#include <iosfwd>
#include <string>

namespace batchcol::cli {

/// Calls `write` on a fresh temporary file created exclusively (O_EXCL, unique name `path`.<pid>.<random>.tmp) in
/// the same directory, then renames it onto `path`. On any failure the temporary file is removed and
/// InputError is thrown (an existing `path` stays untouched).
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace batchcol::cli
