#include "core/mesh/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/common/errors.h"

namespace mq {

std::string read_input_file(const std::string& path, const char* what, std::size_t max_bytes) {
  // O_NONBLOCK: opening a FIFO without a writer must not wait for one; fstat then tells what
  // was opened, with no window between the check and the read.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) MQ_THROW(InvalidInput, path, ": cannot open ", what, ": ", std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    MQ_THROW(InvalidInput, path, ": cannot read ", what, ": ", std::strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    const char* kind = S_ISDIR(st.st_mode)    ? "is a directory"
                       : S_ISFIFO(st.st_mode) ? "is a pipe (FIFO), not a regular file"
                       : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)
                           ? "is a device, not a regular file"
                           : "is not a regular file";
    MQ_THROW(InvalidInput, path, ": cannot read ", what, ": ", kind);
  }
  if (static_cast<unsigned long long>(st.st_size) > max_bytes) {
    ::close(fd);
    MQ_THROW(InvalidInput, path, ": cannot read ", what, ": ", st.st_size, " bytes, more than the ",
             max_bytes, " allowed");
  }
  std::string data(static_cast<std::size_t>(st.st_size), '\0');
  std::size_t got = 0;
  while (got < data.size()) {
    const ssize_t n = ::read(fd, data.data() + got, data.size() - got);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int e = errno;
      ::close(fd);
      MQ_THROW(InvalidInput, path, ": cannot read ", what, ": ", std::strerror(e));
    }
    if (n == 0) break;  // the file shrank while being read
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  data.resize(got);
  return data;
}

}  // namespace mq
