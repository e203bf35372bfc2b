// OutputFile: a temporary file beside the target, renamed into place on success (POSIX).
#include "spaceskip/OutputFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <streambuf>
#include <vector>

namespace spaceskip {

namespace {

std::string dirOf(const std::string& p) {
  const size_t s = p.find_last_of('/');
  if (s == std::string::npos) return ".";
  return s == 0 ? "/" : p.substr(0, s);
}

std::string baseOf(const std::string& p) {
  const size_t s = p.find_last_of('/');
  return s == std::string::npos ? p : p.substr(s + 1);
}

/// `path` with every symbolic link in its last component followed (relative targets are taken
/// from the link's folder); a path that does not exist (yet) is returned as it stands.
std::string followLinks(const std::string& path, const std::string& given) {
  std::string p = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    std::vector<char> buf(size_t(st.st_size > 0 ? st.st_size : 255) + 1);
    const ssize_t n = ::readlink(p.c_str(), buf.data(), buf.size() - 1);
    if (n < 0) throw std::runtime_error(given + ": cannot write: cannot read the symbolic link: " + std::strerror(errno));
    const std::string target(buf.data(), size_t(n));
    p = !target.empty() && target[0] == '/' ? target : dirOf(p) + "/" + target;
  }
  throw std::runtime_error(given + ": cannot write: too many levels of symbolic links");
}

/// A stream buffer over a file descriptor that remembers the first write error (errno).
class FdBuf : public std::streambuf {
 public:
  void attach(int fd) { fd_ = fd; setp(buf_, buf_ + sizeof buf_); }
  int error() const { return error_; }
  /// Writes what is buffered; false (error() set) when the system refused.
  bool drain() {
    const char* p = pbase();
    while (p < pptr() && error_ == 0) {
      const ssize_t n = ::write(fd_, p, size_t(pptr() - p));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) error_ = n < 0 ? errno : EIO;
      else p += n;
    }
    setp(buf_, buf_ + sizeof buf_);
    return error_ == 0;
  }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  int fd_ = -1;
  int error_ = 0;
  char buf_[1 << 16];
};

}  // namespace

struct OutputFile::Impl {
  std::string given;   ///< the path as given (messages)
  std::string target;  ///< links followed
  std::string temp;    ///< empty when writing the target directly (devices, FIFOs)
  int fd = -1;
  bool committed = false;
  FdBuf buf;
  std::ostream out{&buf};

  [[noreturn]] void fail(const std::string& cause) const { throw std::runtime_error(given + ": cannot write: " + cause); }

  void open() {
    target = followLinks(given, given);
    struct stat st {};
    const bool exists = ::stat(target.c_str(), &st) == 0;
    if (exists && S_ISDIR(st.st_mode)) fail("is a directory");
    if (exists && !S_ISREG(st.st_mode)) {
      // Not replaceable by a rename (a device node, a FIFO): written in place. O_NONBLOCK makes
      // a FIFO without a reader an error (ENXIO) instead of a wait; it is cleared after opening.
      fd = ::open(target.c_str(), O_WRONLY | O_CLOEXEC | O_NONBLOCK);
      if (fd < 0) fail(errno == ENXIO ? "no process reads the FIFO" : std::strerror(errno));
      ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
      buf.attach(fd);
      return;
    }
    const std::string dir = dirOf(target);
    struct stat ds {};
    if (::stat(dir.c_str(), &ds) != 0) fail("the folder '" + dir + "' does not exist");
    if (!S_ISDIR(ds.st_mode)) fail("'" + dir + "' is not a folder");
    // A name no one else uses: O_EXCL refuses an existing file, so a collision just tries again.
    const auto seed = uint64_t(std::chrono::steady_clock::now().time_since_epoch().count()) ^ (uint64_t(::getpid()) << 32);
    for (uint64_t attempt = 0; attempt < 100 && fd < 0; ++attempt) {
      char suffix[32];
      std::snprintf(suffix, sizeof suffix, ".%012llx.tmp", (unsigned long long)((seed + attempt * 0x9e3779b97f4a7c15ull) & 0xffffffffffffull));
      temp = dir + "/." + baseOf(target) + suffix;
      fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
      if (fd < 0 && errno != EEXIST) fail("cannot create a temporary file in '" + dir + "': " + std::strerror(errno));
    }
    if (fd < 0) fail("cannot create a temporary file in '" + dir + "' (every name tried exists)");
    if (exists) {
      // The replaced file keeps its mode (and owner, where allowed).
      ::fchmod(fd, st.st_mode & 07777);
      if (::fchown(fd, st.st_uid, st.st_gid) != 0) {
      }
    }
    buf.attach(fd);
  }

  void discard() {
    if (fd >= 0) ::close(fd);
    fd = -1;
    if (!temp.empty()) ::unlink(temp.c_str());
  }
};

OutputFile::OutputFile(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->given = path;
  if (path.empty()) impl_->fail("empty file name");
  try {
    impl_->open();
  } catch (...) {
    impl_->discard();
    throw;
  }
}

OutputFile::~OutputFile() {
  if (!impl_->committed) impl_->discard();
}

std::ostream& OutputFile::stream() { return impl_->out; }

const std::string& OutputFile::path() const { return impl_->given; }

void OutputFile::commit() {
  Impl& m = *impl_;
  if (m.committed) return;
  try {
    m.out.flush();
    if (!m.buf.drain()) m.fail(std::strerror(m.buf.error()));
    if (!m.out) m.fail("the output stream failed");
    // Regular files: the data on disk before the rename, so a crash leaves the old or the new file.
    if (!m.temp.empty() && ::fsync(m.fd) != 0) m.fail(std::strerror(errno));
    const int fd = m.fd;
    m.fd = -1;
    if (::close(fd) != 0) m.fail(std::strerror(errno));
    if (!m.temp.empty() && ::rename(m.temp.c_str(), m.target.c_str()) != 0)
      m.fail("cannot rename the temporary file into place: " + std::string(std::strerror(errno)));
  } catch (...) {
    m.discard();
    throw;
  }
  m.committed = true;
}

void writeOutputFile(const std::string& path, const std::string& bytes) {
  OutputFile f(path);
  f.stream().write(bytes.data(), std::streamsize(bytes.size()));
  f.commit();
}

}  // namespace spaceskip
