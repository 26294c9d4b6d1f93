// AtomicOutputFile: nothing partial at the output path, and no temporary file left behind when
// the writer is stopped by SIGINT or SIGTERM (removed at once) or SIGKILL (removed by the next
// writer of the same name).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/mesh/atomic_file.h"
#include "tests/test_support.h"

namespace mq {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> names_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

// Forks a writer of dir/out.obj that stops half way (the temporary file exists), then sends it
// `sig`. Returns once the child has ended.
void kill_writer_mid_write(const std::string& dir, int sig) {
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    install_temporary_file_cleanup();
    AtomicOutputFile out(dir + "/out.obj");
    out.append(std::string(1 << 20, 'v'));  // past the buffer: bytes on disk
    out.append(std::string(5 << 20, 'f'));
    const char c = 1;
    if (::write(ready[1], &c, 1) != 1) ::_exit(2);
    for (;;) ::pause();
  }
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  ::close(ready[0]);
  ::close(ready[1]);
  ASSERT_EQ(names_in(dir).size(), 1u);  // the temporary file, mid-write
  ASSERT_EQ(::kill(child, sig), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), sig);  // the signal still ends the process as it would have
}

TEST(AtomicOutputFile, SigintAndSigtermLeaveNothing) {
  for (const int sig : {SIGINT, SIGTERM}) {
    const std::string dir = test::temp_dir();
    kill_writer_mid_write(dir, sig);
    EXPECT_TRUE(names_in(dir).empty()) << "signal " << sig << " left " << names_in(dir)[0];
  }
}

TEST(AtomicOutputFile, SigkillLeftoverIsRemovedByTheNextWriter) {
  const std::string dir = test::temp_dir();
  kill_writer_mid_write(dir, SIGKILL);
  ASSERT_EQ(names_in(dir).size(), 1u);  // SIGKILL cannot be caught
  EXPECT_EQ(names_in(dir)[0].rfind(".out.obj.tmp-", 0), 0u);
  // Another name's writer leaves it alone; the same name's removes it (its writer is gone).
  write_file_atomically(dir + "/other.obj", "x");
  EXPECT_EQ(names_in(dir).size(), 2u);
  write_file_atomically(dir + "/out.obj", "complete");
  std::vector<std::string> names = names_in(dir);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"other.obj", "out.obj"}));
}

TEST(AtomicOutputFile, RunningWritersTemporaryIsKept) {
  const std::string dir = test::temp_dir();
  AtomicOutputFile first(dir + "/out.obj");  // this process is alive: its file must stay
  first.append("a");
  write_file_atomically(dir + "/out.obj", "b");
  EXPECT_EQ(names_in(dir).size(), 2u);
  first.commit();
  EXPECT_EQ(names_in(dir).size(), 1u);
}

}  // namespace
}  // namespace mq
