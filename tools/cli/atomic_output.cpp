#include "cli/atomic_output.hpp"

#include <batchcol/errors.hpp>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <ostream>
#include <random>
#include <streambuf>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace batchcol::cli {

namespace {

// An output stream buffer over a file descriptor we created ourselves: the temporary file is opened with O_EXCL, so
// writing through a second open() by name (as std::ofstream would) could follow a symlink or FIFO swapped in.
class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd) { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
  bool failed() const { return failed_; }

 protected:
  int_type overflow(int_type c) override {
    if (!flush_buffer()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return flush_buffer() ? 0 : -1; }

 private:
  bool flush_buffer() {
    const char* p = pbase();
    while (p < pptr()) {
      const ssize_t n = ::write(fd_, p, static_cast<std::size_t>(pptr() - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        failed_ = true;
        return false;
      }
      p += n;
    }
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return true;
  }

  int fd_;
  bool failed_ = false;
  std::array<char, 1 << 16> buffer_{};
};

// Creates a fresh file next to `path` with O_CREAT | O_EXCL (never an existing file, symlink or FIFO) and returns its
// descriptor; `tmp` receives its name. A random suffix makes concurrent runs with the same --out use distinct files.
int create_unique_temporary(const std::string& path, std::string& tmp) {
  std::random_device entropy;
  std::mt19937_64 random((static_cast<std::uint64_t>(entropy()) << 32) ^ entropy() ^
                         static_cast<std::uint64_t>(::getpid()));
  int last_errno = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    char suffix[40];
    std::snprintf(suffix, sizeof suffix, ".%d.%016llx.tmp", static_cast<int>(::getpid()),
                  static_cast<unsigned long long>(random()));
    tmp = path + suffix;
    // 0666 filtered by the umask: the final file gets the permissions a plain ofstream would have given it.
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0) return fd;
    last_errno = errno;
    if (errno != EEXIST) break;
  }
  throw InputError(path + ": cannot create a temporary file next to it: " + std::strerror(last_errno));
}

}  // namespace

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(path + ": is a directory, expected an output file");
  // Owns the temporary file until the rename: any exception (from `write` too) closes and removes it.
  struct Temporary {
    int fd = -1;
    std::string name;
    ~Temporary() {
      if (fd >= 0) ::close(fd);
      if (!name.empty()) ::unlink(name.c_str());
    }
  } tmp;
  tmp.fd = create_unique_temporary(path, tmp.name);
  {
    FdBuf buffer(tmp.fd);
    std::ostream out(&buffer);
    write(out);
    out.flush();
    if (!out || buffer.failed()) throw InputError(path + ": write failed: " + std::strerror(errno));
  }
  const int fd = tmp.fd;
  tmp.fd = -1;
  if (::close(fd) != 0) throw InputError(path + ": write failed: " + std::strerror(errno));
  if (std::rename(tmp.name.c_str(), path.c_str()) != 0) {
    throw InputError("cannot rename the temporary file onto " + path + ": " + std::strerror(errno));
  }
  tmp.name.clear();
}

}  // namespace batchcol::cli
