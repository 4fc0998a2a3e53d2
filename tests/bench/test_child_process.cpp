// The process plumbing of the tests and benches (tests/support/child_process.hpp), with
// /bin/sh children: a child that never gets ready and ignores SIGTERM is
// killed and reaped, one that honours SIGTERM is stopped by it, one that
// exits early is reported with its code and last log line, a failed execve
// is told apart, READY=1 is found among other notifications, and the
// temporary folder goes with everything in it. Timeouts here only bound a
// wait; no duration is asserted.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "support/child_process.hpp"

namespace mpm::test {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

// No child of this process, running or exited but not reaped.
bool no_child_left() { return ::waitpid(-1, nullptr, WNOHANG) == -1 && errno == ECHILD; }

// Polls the child's log until its last line is `line` (the child has run up
// to there), at most 30 s.
bool wait_for_log_line(const std::string& log, const std::string& line) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (last_nonempty_line(log) != line) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(milliseconds(10));
  }
  return true;
}

// Sends one datagram to a bound notify socket, as sd_notify would.
bool notify(const std::string& socket_path, const std::string& text) {
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::memcpy(addr.sun_path, socket_path.c_str(), std::min(socket_path.size() + 1, sizeof addr.sun_path));
  const bool sent = fd >= 0 && ::sendto(fd, text.data(), text.size(), 0, reinterpret_cast<sockaddr*>(&addr),
                                        sizeof addr) == static_cast<ssize_t>(text.size());
  if (fd >= 0) ::close(fd);
  return sent;
}

std::vector<std::string> sh(const std::string& script) { return {"/bin/sh", "-c", script}; }

// A temporary folder with a notify socket bound in it, as systemd gives one
// (ok() makes both; `why` says what failed).
struct NotifyDir {
  TempDir dir;
  NotifySocket sock;
  std::string path = dir.file("notify.sock");
  std::string why;
  bool ok() { return dir.ok(why) && sock.bind(path, why); }
};

TEST(TempDir, MadeUnderTmpdirAndRemovedWithItsContents) {
  std::string kept;
  {
    TempDir dir("mpm-child-test");
    std::string why;
    ASSERT_TRUE(dir.ok(why)) << why;
    kept = dir.path();
    EXPECT_EQ(fs::path(kept).parent_path(), fs::temp_directory_path());
    EXPECT_EQ(fs::path(kept).filename().string().rfind("mpm-child-test-", 0), 0u) << kept;
    ASSERT_TRUE(write_text_file(dir.file("a.txt"), "first\n\nlast\n\n"));
    EXPECT_EQ(last_nonempty_line(dir.file("a.txt")), "last");
    fs::create_directory(dir.file("sub"));
    ASSERT_TRUE(write_text_file(dir.file("sub/b.txt"), "x"));
  }
  EXPECT_FALSE(fs::exists(kept));
  EXPECT_EQ(last_nonempty_line(kept + "/a.txt"), "") << "a missing file has no last line";
}

TEST(ChildEnvironment, OurNotifySocketAndNoWatchdog) {
  ::setenv("NOTIFY_SOCKET", "/run/systemd/notify", 1);
  ::setenv("WATCHDOG_USEC", "1000000", 1);
  ::setenv("MPM_CHILD_TEST_MARK", "kept", 1);
  const std::vector<std::string> env = environment_with_notify_socket("/tmp/x/notify.sock");
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("MPM_CHILD_TEST_MARK");
  EXPECT_EQ(std::count_if(env.begin(), env.end(), [](const std::string& e) { return e.rfind("NOTIFY_SOCKET=", 0) == 0; }),
            1);
  EXPECT_NE(std::find(env.begin(), env.end(), "NOTIFY_SOCKET=/tmp/x/notify.sock"), env.end());
  EXPECT_EQ(std::find(env.begin(), env.end(), "WATCHDOG_USEC=1000000"), env.end());
  EXPECT_NE(std::find(env.begin(), env.end(), "MPM_CHILD_TEST_MARK=kept"), env.end());
}

TEST(ChildProcess, NeverReadyAndIgnoringSigtermIsKilledAndReaped) {
  NotifyDir n;
  ASSERT_TRUE(n.ok()) << n.why;
  auto& [dir, sock, path, why] = n;
  pid_t pid = 0;
  {
    ChildProcess child(milliseconds(200));
    ASSERT_TRUE(child.start(sh("trap '' TERM; echo armed; while :; do sleep 0.05; done"),
                            environment_with_notify_socket(path), dir.file("child.log"), why))
        << why;
    pid = child.pid();
    ASSERT_TRUE(wait_for_log_line(dir.file("child.log"), "armed")) << "the child never ran its trap";
    EXPECT_EQ(wait_for_ready(sock, child, milliseconds(200)), ReadyWait::kTimedOut);
    EXPECT_TRUE(child.running());
    child.stop();
    EXPECT_FALSE(child.running());
    ASSERT_TRUE(child.exit_status());
    EXPECT_TRUE(WIFSIGNALED(*child.exit_status()) && WTERMSIG(*child.exit_status()) == SIGKILL)
        << describe_exit(*child.exit_status());
    EXPECT_FALSE(read_proc_memory(pid)) << "a reaped child has no /proc entry";
  }
  EXPECT_EQ(::kill(pid, 0), -1) << "the child still exists";
  EXPECT_TRUE(no_child_left());
}

TEST(ChildProcess, OneThatHonoursSigtermIsStoppedByIt) {
  TempDir dir;
  std::string why;
  ASSERT_TRUE(dir.ok(why)) << why;
  ChildProcess child(std::chrono::seconds(30));
  ASSERT_TRUE(child.start(sh("echo armed; exec sleep 60"), {}, dir.file("child.log"), why)) << why;
  ASSERT_TRUE(wait_for_log_line(dir.file("child.log"), "armed"));
  child.stop();
  ASSERT_TRUE(child.exit_status());
  EXPECT_EQ(describe_exit(*child.exit_status()), std::string("was killed by signal ") + strsignal(SIGTERM));
  EXPECT_TRUE(no_child_left());
}

TEST(ChildProcess, ExitingBeforeReadyIsReportedWithItsCodeAndLastLogLine) {
  NotifyDir n;
  ASSERT_TRUE(n.ok()) << n.why;
  auto& [dir, sock, path, why] = n;
  ::setenv("WATCHDOG_USEC", "1000000", 1);
  const auto env = environment_with_notify_socket(path);
  ::unsetenv("WATCHDOG_USEC");
  ChildProcess child(milliseconds(200));
  // Exit code 4 or 5 when the environment is not what we gave it.
  ASSERT_TRUE(child.start(sh("test \"$NOTIFY_SOCKET\" = '" + path + "' || exit 4\n" +
                             "test -z \"$WATCHDOG_USEC\" || exit 5\n" +
                             "echo '<6>starting' >&2; echo '<3>broken on purpose' >&2; exit 3"),
                          env, dir.file("child.log"), why))
      << why;
  EXPECT_EQ(wait_for_ready(sock, child, std::chrono::seconds(60)), ReadyWait::kExited);
  ASSERT_TRUE(child.exit_status());
  EXPECT_EQ(describe_exit(*child.exit_status()), "exited with code 3");
  EXPECT_EQ(last_nonempty_line(dir.file("child.log")), "<3>broken on purpose");
  EXPECT_TRUE(no_child_left());
}

TEST(ChildProcess, AFailedExecveExitsWith127AndSaysSo) {
  TempDir dir;
  std::string why;
  ASSERT_TRUE(dir.ok(why)) << why;
  EXPECT_FALSE(is_executable_file(dir.file("missing-program")));
  EXPECT_FALSE(is_executable_file(dir.path())) << "a folder is not a program";
  EXPECT_TRUE(is_executable_file("/bin/sh"));
  ChildProcess child(milliseconds(200));
  ASSERT_TRUE(child.start({dir.file("missing-program")}, {}, dir.file("child.log"), why)) << why;
  while (child.running()) std::this_thread::sleep_for(milliseconds(5));
  ASSERT_TRUE(child.exit_status());
  EXPECT_EQ(describe_exit(*child.exit_status()), "exited with code 127");
  EXPECT_NE(last_nonempty_line(dir.file("child.log")).find("execve of missing-program failed"), std::string::npos);
  EXPECT_TRUE(no_child_left());
}

// The tests' way: started at once, stdout and stderr to their own files,
// our environment plus the given entries, the exit code (128 + signal).
TEST(ChildProcess, ForTestsSeparateOutputsAddedEnvironmentAndExitCodes) {
  TempDir dir;
  std::string why;
  ASSERT_TRUE(dir.ok(why)) << why;
  {
    ChildProcess child(sh("echo \"out $MPM_CHILD_TEST\"; echo err >&2; exit 4"), dir.file("out"), dir.file("err"),
                       {{"MPM_CHILD_TEST", "set"}});
    ASSERT_TRUE(child.started());
    EXPECT_EQ(child.wait_exit(std::chrono::seconds(30)), 4);
    EXPECT_EQ(child.stdout_text(), "out set\n");
    EXPECT_EQ(child.stderr_text(), "err\n");
  }
  {
    ChildProcess child(sh("sleep 30"), dir.file("out2"), dir.file("err2"));
    ASSERT_TRUE(child.started());
    EXPECT_FALSE(child.wait_exit(milliseconds(50))) << "still running";
    child.signal(SIGTERM);
    EXPECT_EQ(child.wait_exit(std::chrono::seconds(30)), 128 + SIGTERM);
  }
  EXPECT_TRUE(no_child_left());
}

TEST(NotifySocket, ReadyIsFoundAmongOtherNotifications) {
  NotifyDir n;
  ASSERT_TRUE(n.ok()) << n.why;
  auto& [dir, sock, path, why] = n;
  ASSERT_TRUE(notify(path, "STATUS=starting"));
  EXPECT_FALSE(sock.receive("READY=1", std::chrono::seconds(30)));

  ChildProcess child(std::chrono::seconds(30));
  ASSERT_TRUE(child.start(sh("exec sleep 60"), {}, dir.file("child.log"), why)) << why;
  ASSERT_TRUE(notify(path, "STATUS=watching\nREADY=1"));
  EXPECT_EQ(wait_for_ready(sock, child, std::chrono::seconds(30)), ReadyWait::kReady);
  EXPECT_TRUE(child.running());
  child.stop();
  EXPECT_TRUE(no_child_left());

  NotifySocket too_long;
  EXPECT_FALSE(too_long.bind(dir.file(std::string(200, 'x')), why));
  EXPECT_NE(why.find("too long"), std::string::npos) << why;
}

TEST(ProcMemory, OfThisProcess) {
  const auto m = read_proc_memory(::getpid());
  ASSERT_TRUE(m);
  EXPECT_GT(m->vm_rss_mb, 0.0);
  EXPECT_GE(m->vm_hwm_mb, m->vm_rss_mb);
  EXPECT_GT(m->rss_anon_mb, 0.0);
  EXPECT_GT(m->rss_file_mb, 0.0);
  EXPECT_FALSE(read_proc_memory(-1));
}

}  // namespace
}  // namespace mpm::test
