#include "core/mesh/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>

#include "core/common/errors.h"
#include "core/common/fnv1a.h"

namespace mq {
namespace {

// Temporary files open now, for the signal handler: fixed slots of fixed buffers, claimed and
// released with atomics, so that the handler reads them without locks or allocation.
constexpr int kSlots = 16;
constexpr size_t kPathMax = 4096;
char g_temp_path[kSlots][kPathMax];
std::atomic<int> g_temp_state[kSlots];  // 0 free, 1 being written, 2 a path to remove

int claim_slot(const std::string& temp) {
  if (temp.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_temp_state[i].compare_exchange_strong(expected, 1)) {
      std::memcpy(g_temp_path[i], temp.c_str(), temp.size() + 1);
      g_temp_state[i].store(2);
      return i;
    }
  }
  return -1;  // more than kSlots files open at once: that one is cleaned on the next run
}

void release_slot(int i) {
  if (i >= 0) g_temp_state[i].store(0);
}

extern "C" void remove_temporaries_and_reraise(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_temp_state[i].load() == 2) ::unlink(g_temp_path[i]);  // async-signal-safe
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

// The "NAME" part of a temporary's name ".NAME.tmp-PID-XXXXXX": NAME itself when the whole fits
// in a file name (NAME_MAX, 255 bytes), else NAME cut short and told apart by a hash of it, so a
// legal output name of up to 255 bytes can still be written (issue 28).
std::string temporary_stem(const std::string& name) {
  constexpr size_t kNameMax = 255;
  constexpr size_t kDecoration = 1 + 5 + 10 + 1 + 6;  // ".", ".tmp-", a pid, "-", XXXXXX
  if (name.size() + kDecoration <= kNameMax) return name;
  std::uint64_t h = kFnv1aOffset;
  fnv1a(h, name.data(), name.size());
  char hash[18];
  std::snprintf(hash, sizeof hash, "~%016llx", static_cast<unsigned long long>(h));
  return name.substr(0, kNameMax - kDecoration - 17) + hash;
}

// Removes ".NAME.tmp-PID-*" files in dir left by writers that no longer run (killed by SIGKILL
// or a power cut); a running writer's file is kept.
void remove_stale_temporaries(const std::filesystem::path& dir, const std::string& name) {
  namespace fs = std::filesystem;
  const std::string prefix = "." + temporary_stem(name) + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    if (f.rfind(prefix, 0) != 0) continue;
    const std::string rest = f.substr(prefix.size());
    const size_t dash = rest.find('-');
    if (dash == std::string::npos || dash == 0) continue;
    char* stop = nullptr;
    const long pid = std::strtol(rest.c_str(), &stop, 10);
    if (stop != rest.c_str() + dash || pid <= 0) continue;
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // still running
    fs::remove(it->path(), ec);
  }
}

}  // namespace

void install_temporary_file_cleanup() {
  struct sigaction sa {};
  sa.sa_handler = remove_temporaries_and_reraise;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &sa, nullptr);
}

AtomicOutputFile::AtomicOutputFile(const std::string& path) : path_(path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  MQ_CHECK(!target.filename().empty(), InvalidInput, path, ": not a file name");
  std::error_code ec;
  MQ_CHECK(!fs::is_directory(target, ec), InvalidInput, path, ": is a directory");
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  remove_stale_temporaries(dir, target.filename().string());
  std::string pattern = (dir / ("." + temporary_stem(target.filename().string()) + ".tmp-" +
                                std::to_string(::getpid()) + "-XXXXXX"))
                            .string();
  const int fd = ::mkstemp(pattern.data());
  if (fd < 0)
    MQ_THROW(Error, path, ": cannot write: cannot create a file in '", dir.string(),
             "': ", std::strerror(errno));
  temp_ = pattern;
  slot_ = claim_slot(temp_);
  // mkstemp creates 0600; keep an existing file's mode, else the usual 0644.
  struct stat st;
  const mode_t mode = ::stat(path.c_str(), &st) == 0 ? (st.st_mode & 07777) : 0644;
  ::fchmod(fd, mode);
  file_ = ::fdopen(fd, "wb");
  if (!file_) {
    ::close(fd);
    std::remove(temp_.c_str());
    release_slot(slot_);
    MQ_THROW(Error, path, ": cannot write: ", std::strerror(errno));
  }
  buffer_.resize(kChunk + kSlack);
}

AtomicOutputFile::~AtomicOutputFile() {
  if (file_) std::fclose(file_);
  if (!committed_) std::remove(temp_.c_str());
  release_slot(slot_);
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

void AtomicOutputFile::finish() {
  if (!file_) return;
  flush();
  const bool ok = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
  const int err = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) MQ_THROW(Error, path_, ": cannot write: ", std::strerror(ok ? errno : err));
}

void commit_together(AtomicOutputFile& first, AtomicOutputFile& second) {
  commit_together({&first, &second});
}

void commit_together(const std::vector<AtomicOutputFile*>& files) {
  namespace fs = std::filesystem;
  if (files.empty()) return;
  for (AtomicOutputFile* f : files) f->finish();
  const std::string& last_path = files.back()->path_;
  const fs::path dir =
      fs::path(last_path).has_parent_path() ? fs::path(last_path).parent_path() : fs::path(".");
  // flock on the directory itself: no lock file to leave behind; released by close().
  const int lock = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock >= 0) ::flock(lock, LOCK_EX);
  struct Unlock {
    int fd;
    ~Unlock() {
      if (fd >= 0) ::close(fd);
    }
  } unlock{lock};
  // Hard links keep the old files while the new ones take their names; a failed rename puts
  // back every file renamed before it (or removes it where there was none).
  std::vector<std::string> kept(files.size());
  std::vector<char> had_old(files.size(), 0);
  for (size_t i = 0; i < files.size(); ++i) {
    AtomicOutputFile& f = *files[i];
    if (i + 1 < files.size()) {
      kept[i] = f.temp_ + "-old";
      had_old[i] = ::link(f.path_.c_str(), kept[i].c_str()) == 0;
    }
    if (std::rename(f.temp_.c_str(), f.path_.c_str()) != 0) {
      const int err = errno;
      std::string restored;
      for (size_t j = 0; j < i; ++j) {
        AtomicOutputFile& g = *files[j];
        if (had_old[j])
          std::rename(kept[j].c_str(), g.path_.c_str());
        else
          ::unlink(g.path_.c_str());
        restored += (restored.empty() ? "" : ", ") + g.path_;
      }
      if (had_old[i]) ::unlink(kept[i].c_str());
      MQ_THROW(Error, f.path_, ": cannot write: rename failed: ", std::strerror(err),
               restored.empty() ? "" : " (", restored, restored.empty() ? "" : " left as it was)");
    }
    f.committed_ = true;
    release_slot(f.slot_);
    f.slot_ = -1;
  }
  for (size_t i = 0; i < files.size(); ++i)
    if (had_old[i]) ::unlink(kept[i].c_str());
}

void commit_with(AtomicOutputFile& file, const std::string& companion_path,
                 const std::function<std::string()>& companion_bytes, AtomicOutputFile* before) {
  std::vector<AtomicOutputFile*> files;
  if (before) files.push_back(before);
  files.push_back(&file);
  if (companion_path.empty()) {
    if (files.size() == 1)
      file.commit();
    else
      commit_together(files);
    return;
  }
  // The companion's bytes are made once the others are written out (a --stats file holding
  // the write's own time); it is renamed last.
  for (AtomicOutputFile* f : files) f->finish();
  AtomicOutputFile companion(companion_path);
  companion.append(companion_bytes ? companion_bytes() : std::string());
  files.push_back(&companion);
  commit_together(files);
}

void AtomicOutputFile::commit() {
  finish();
  if (std::rename(temp_.c_str(), path_.c_str()) != 0)
    MQ_THROW(Error, path_, ": cannot write: rename failed: ", std::strerror(errno));
  committed_ = true;
  release_slot(slot_);  // the name is the output's now: a signal must not remove it
  slot_ = -1;
}

void AtomicOutputFile::flush() {
  write_raw(buffer_.data(), used_);
  used_ = 0;
#ifdef __linux__
  // Each full chunk handed to the kernel starts its write-back now, so that it overlaps the
  // making of the next chunks and commit()'s fsync waits only for the tail (ivy wall: fsync
  // 0.3 s of the 0.9 s writing 2M faces). A hint: fsync still decides, and reports errors.
  if (written_ - started_ >= kChunk && std::fflush(file_) == 0) {
    ::sync_file_range(::fileno(file_), static_cast<off64_t>(started_),
                      static_cast<off64_t>(written_ - started_), SYNC_FILE_RANGE_WRITE);
    started_ = written_;
  }
#endif
}

void AtomicOutputFile::write_raw(const char* s, size_t n) {
  if (n > 0 && std::fwrite(s, 1, n, file_) != n)
    MQ_THROW(Error, path_, ": cannot write: ", std::strerror(errno));
  written_ += n;
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  AtomicOutputFile out(path);
  out.append(bytes);
  out.commit();
}

}  // namespace mq
