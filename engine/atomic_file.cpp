#include "engine/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "engine/error.h"

namespace ballpit {

namespace {

// Where the bytes go before the rename: beside the target, so the rename stays in one file system.
std::string temporary_path(const std::string& path) { return path + ".tmp." + std::to_string(::getpid()); }

}  // namespace

void check_writable(const std::string& path) {
  if (path.empty()) throw Error("cannot write a file with an empty name");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) throw Error("cannot write '" + path + "': it is a folder");
  // The same temporary file the write makes, made and removed at once: whatever the folder
  // would refuse then (missing, read-only, not a folder), it refuses now.
  const std::string tmp = temporary_path(path);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error("cannot write '" + path + "' (create temporary file: " + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(tmp.c_str());
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  std::string tmp = temporary_path(path);
  auto fail = [&](const char* step) {
    std::string why = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw Error("cannot write '" + path + "' (" + step + ": " + why + "); the previous file is untouched");
  };
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail("create temporary file");
  std::size_t done = 0;
  while (done < bytes.size()) {
    ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ::close(fd);
      fail("write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    fail("fsync");
  }
  if (::close(fd) != 0) fail("close");
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail("rename");
}

}  // namespace ballpit
