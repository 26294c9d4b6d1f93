// Writing files so that a failed run never leaves a partial output: the bytes go to a temporary
// file in the destination directory, which is renamed over the destination only when complete.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace mq {

// Buffered output to a temporary file beside `path`, renamed over it by commit(). The
// destructor removes the temporary file when commit() was not reached, so `path` is never left
// partial. A new file gets mode 0644, a replaced one keeps its mode.
// Throws Error naming `path` on any I/O failure; InvalidInput when `path` is a directory.
class AtomicOutputFile {
 public:
  explicit AtomicOutputFile(const std::string& path);
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;
  ~AtomicOutputFile();

  // Room for at least kSlack bytes at cursor(); advance with commit_bytes().
  char* cursor() { return buffer_.data() + used_; }
  void commit_bytes(char* end);
  void append(const char* s, size_t n);
  void append(std::string_view s) { append(s.data(), s.size()); }
  // Flushes, syncs and renames the temporary file over `path`.
  void commit();
  // Flushes, syncs and closes the temporary file (the part of commit() that can fail on a full
  // disk), leaving the rename to commit() or commit_together(). Idempotent.
  void finish();

  static constexpr size_t kSlack = 1024;

 private:
  friend void commit_together(const std::vector<AtomicOutputFile*>& files);
  static constexpr size_t kChunk = size_t(1) << 22;
  void flush();
  void write_raw(const char* s, size_t n);

  std::string path_;
  std::string temp_;
  std::FILE* file_ = nullptr;
  std::vector<char> buffer_;
  size_t used_ = 0;
  size_t written_ = 0;  // bytes handed to the file
  size_t started_ = 0;  // of them, those whose write-back was started
  bool committed_ = false;
  int slot_ = -1;  // in the signal handler's list of temporaries
};

// Removes the temporary files of AtomicOutputFiles still open when SIGINT or SIGTERM arrives,
// then lets the signal end the process as it would have (default action). Call once, early in
// main(). A SIGKILL cannot be caught: its temporary file (".NAME.tmp-PID-XXXXXX", PID the
// writer's) is removed by the next AtomicOutputFile for the same NAME once no process PID runs.
void install_temporary_file_cleanup();

// Commits two files that belong together (an OBJ and its .mtl) so that readers find both new
// or both old: both are written out before either is renamed (a full disk changes neither);
// the renames run under an exclusive lock on their directory (two runs writing the same pair
// do not interleave), first's then second's; if second's fails (an immutable old file), first's
// old file is put back. Throws Error naming the file that failed.
void commit_together(AtomicOutputFile& first, AtomicOutputFile& second);

// commit_together for any number of files (in order; the directory locked is the last's): all
// are written out before any is renamed; a failed rename puts back the files renamed before it.
void commit_together(const std::vector<AtomicOutputFile*>& files);

// Commits `file` (after `before`, when given: an OBJ's .mtl) together with a companion file at
// `companion_path` (none when empty) whose bytes `companion_bytes` makes once the others are
// written out, so that it can report their writing (issue 28: a --stats file that failed on a
// full disk after the mesh was replaced). All new or all old.
void commit_with(AtomicOutputFile& file, const std::string& companion_path,
                 const std::function<std::string()>& companion_bytes,
                 AtomicOutputFile* before = nullptr);

// Writes `bytes` to `path` atomically (an AtomicOutputFile written at once).
void write_file_atomically(const std::string& path, std::string_view bytes);

}  // namespace mq
