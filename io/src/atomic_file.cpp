#include "sewn/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "sewn/io/errors.hpp"

namespace sewn::io {

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  const std::filesystem::path part = path.string() + ".part";
  const int fd = ::open(part.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw FileError(path.string(), 0, std::string("cannot open for writing: ") + std::strerror(errno));
  int error = 0;
  for (std::size_t done = 0; done < content.size() && !error;) {
    const ::ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno != EINTR) {
      error = errno;
    } else if (n == 0) {
      error = EIO;
    }
  }
  // close reports delayed write errors (quota, network file systems)
  if (::close(fd) != 0 && !error) error = errno;
  if (error) {
    ::unlink(part.c_str());
    throw FileError(path.string(), 0, std::string("write error: ") + std::strerror(error) + "; the previous content is kept");
  }
  publish_part(part, path);
}

void publish_part(const std::filesystem::path& part, const std::filesystem::path& path) {
  if (::rename(part.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(part.c_str());
    throw FileError(path.string(), 0, std::string("cannot move the finished file into place: ") + std::strerror(error));
  }
}

}  // namespace sewn::io
