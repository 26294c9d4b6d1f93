#include "core/atomic_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "core/errors.h"

namespace mq {

AtomicOutputFile::AtomicOutputFile(const std::string& path) : path_(path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  MQ_CHECK(!target.filename().empty(), InvalidInput, path, ": not a file name");
  std::error_code ec;
  MQ_CHECK(!fs::is_directory(target, ec), InvalidInput, path, ": is a directory");
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string pattern = (dir / ("." + target.filename().string() + ".tmp-XXXXXX")).string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0)
    MQ_THROW(Error, path, ": cannot write: cannot create a file in '", dir.string(),
             "': ", std::strerror(errno));
  temp_ = pattern;
  // mkstemp creates 0600; keep an existing file's mode, else the usual 0644.
  struct stat st;
  const mode_t mode = ::stat(path.c_str(), &st) == 0 ? (st.st_mode & 07777) : 0644;
  ::fchmod(fd, mode);
  file_ = ::fdopen(fd, "wb");
  if (!file_) {
    ::close(fd);
    std::remove(temp_.c_str());
    MQ_THROW(Error, path, ": cannot write: ", std::strerror(errno));
  }
  buffer_.resize(kChunk + kSlack);
}

AtomicOutputFile::~AtomicOutputFile() {
  if (file_) std::fclose(file_);
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicOutputFile::commit_bytes(char* end) {
  used_ = static_cast<size_t>(end - buffer_.data());
  if (used_ >= kChunk) flush();
}

void AtomicOutputFile::append(const char* s, size_t n) {
  if (used_ + n > buffer_.size()) flush();
  if (n > buffer_.size()) {
    write_raw(s, n);
    return;
  }
  std::memcpy(buffer_.data() + used_, s, n);
  used_ += n;
}

void AtomicOutputFile::commit() {
  flush();
  const bool ok = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  const int err = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) MQ_THROW(Error, path_, ": cannot write: ", std::strerror(ok ? errno : err));
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    MQ_THROW(Error, path_, ": cannot write: rename failed: ", std::strerror(errno));
  committed_ = true;
}

void AtomicOutputFile::flush() {
  write_raw(buffer_.data(), used_);
  used_ = 0;
}

void AtomicOutputFile::write_raw(const char* s, size_t n) {
  if (n > 0 && std::fwrite(s, 1, n, file_) != n)
    MQ_THROW(Error, path_, ": cannot write: ", std::strerror(errno));
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  AtomicOutputFile out(path);
  out.append(bytes);
  out.commit();
}

}  // namespace mq
