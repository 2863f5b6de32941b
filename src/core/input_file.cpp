// Opening an input file safely (input_file.hpp).
#include "afmkit/core/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <streambuf>
#include <utility>

#include <fmt/format.h>

#include "afmkit/core/error.hpp"
#include "afmkit/core/memory.hpp"

namespace afmkit::files {

namespace {

/// An open file descriptor, closed on destruction.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

/// Opens `path` without blocking (a FIFO opened for reading would wait for a writer), refuses anything but a
/// regular file, then makes reads blocking again. Returns the descriptor and the file's size.
int open_regular(const std::string& path, const std::string& what, std::uintmax_t& size) {
  if (path.find('\0') != std::string::npos)
    throw InputError(fmt::format("{} path holds a NUL character: a path cannot contain one", what));
  Descriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (fd.get() < 0) throw InputError(fmt::format("cannot open {} '{}': {}", what, path, std::strerror(errno)));
  struct stat st {};
  if (::fstat(fd.get(), &st) != 0)
    throw InputError(fmt::format("cannot read {} '{}': {}", what, path, std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw InputError(fmt::format("{} '{}' is {}, not a regular file", what, path, kind_of(st.st_mode)));
  const int flags = ::fcntl(fd.get(), F_GETFL);
  if (flags < 0 || ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK) != 0)
    throw InputError(fmt::format("cannot read {} '{}': {}", what, path, std::strerror(errno)));
  size = static_cast<std::uintmax_t>(st.st_size);
  return fd.release();
}

/// read(2) that retries when interrupted; -1 on an error.
ssize_t read_some(int fd, char* data, std::size_t size) {
  for (;;) {
    const ssize_t n = ::read(fd, data, size);
    if (n >= 0 || errno != EINTR) return n;
  }
}

/// A read-only stream buffer over a file descriptor it owns.
class DescriptorBuffer final : public std::streambuf {
 public:
  DescriptorBuffer(int fd, std::string what, std::string path)
      : fd_(fd), what_(std::move(what)), path_(std::move(path)) {}

 protected:
  int_type underflow() override {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    const ssize_t n = read_some(fd_.get(), buffer_, sizeof buffer_);
    if (n < 0) throw InputError(fmt::format("cannot read {} '{}': {}", what_, path_, std::strerror(errno)));
    if (n == 0) return traits_type::eof();
    setg(buffer_, buffer_, buffer_ + n);
    return traits_type::to_int_type(*gptr());
  }

 private:
  Descriptor fd_;
  std::string what_, path_;
  char buffer_[1 << 16];
};

/// An istream owning its buffer.
class DescriptorStream final : public std::istream {
 public:
  DescriptorStream(int fd, std::string what, std::string path)
      : std::istream(nullptr), buffer_(fd, std::move(what), std::move(path)) {
    rdbuf(&buffer_);
    exceptions(std::ios::badbit);  // a read error is an InputError from the buffer, never a silent end of file
  }

 private:
  DescriptorBuffer buffer_;
};

std::string bytes_text(std::uintmax_t bytes) {
  const double b = static_cast<double>(bytes);
  if (b >= 1024.0 * 1024.0 * 1024.0) return fmt::format("{:.3g} GiB", b / (1024.0 * 1024.0 * 1024.0));
  if (b >= 1024.0 * 1024.0) return fmt::format("{:.3g} MiB", b / (1024.0 * 1024.0));
  if (b >= 1024.0) return fmt::format("{:.3g} KiB", b / 1024.0);
  return fmt::format("{} bytes", bytes);
}

}  // namespace

std::uintmax_t input_size_limit() { return memory::available_bytes() / 4; }

std::string read_input_file(const std::string& path, const std::string& what, std::uintmax_t max_bytes) {
  std::uintmax_t size = 0;
  Descriptor fd(open_regular(path, what, size));
  const std::uintmax_t memory_limit = input_size_limit();
  const std::uintmax_t limit = std::min(max_bytes, memory_limit);
  auto too_large = [&](std::uintmax_t seen) {
    if (max_bytes <= memory_limit)
      return InputError(fmt::format("{} '{}' has {}, more than the {} such a file may have", what, path,
                                    bytes_text(seen), bytes_text(max_bytes)));
    return InputError(fmt::format("{} '{}' has {}, more than the {} this run may read (a quarter of the memory "
                                  "usable now: MemAvailable, ulimit -v, AFMKIT_MEMORY_LIMIT)",
                                  what, path, bytes_text(seen), bytes_text(memory_limit)));
  };
  if (size > limit) throw too_large(size);
  std::string text;
  text.resize(static_cast<std::size_t>(size));
  std::size_t got = 0;
  for (;;) {  // the size may change while reading (a file being written): never read beyond the limit
    if (got == text.size()) {
      if (got > limit) throw too_large(got);
      text.resize(std::max<std::size_t>(got + 1, std::min<std::uintmax_t>(2 * got + 4096, limit + 1)));
    }
    const ssize_t n = read_some(fd.get(), text.data() + got, text.size() - got);
    if (n < 0) throw InputError(fmt::format("cannot read {} '{}': {}", what, path, std::strerror(errno)));
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  if (got > limit) throw too_large(got);
  text.resize(got);
  return text;
}

std::unique_ptr<std::istream> open_input_file(const std::string& path, const std::string& what) {
  std::uintmax_t size = 0;
  const int fd = open_regular(path, what, size);
  return std::make_unique<DescriptorStream>(fd, what, path);
}

}  // namespace afmkit::files
