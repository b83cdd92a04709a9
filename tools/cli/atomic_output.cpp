#include "cli/atomic_output.hpp"

#include <batchcol/errors.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

namespace batchcol::cli {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path + ": is a directory, expected an output file");
  const std::string tmp = path + ".tmp";
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(tmp + ": cannot create: " + std::strerror(errno));
    write(out);
    out.close();
    if (!out) throw InputError(tmp + ": write failed");
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
      throw InputError("cannot rename " + tmp + " to " + path + ": " + std::strerror(errno));
    }
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
}

}  // namespace batchcol::cli
