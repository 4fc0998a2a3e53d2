// The process plumbing the tests and the benches share (one implementation:
// mpm_test_support). A bench measures a real service the way systemd runs
// it, a test drives mpmd and mpm as separate processes: a program started with
// fork/exec (output to a file, dying with us), told where to send sd_notify
// messages (an AF_UNIX datagram socket of ours named by NOTIFY_SOCKET),
// waited for until it says READY=1, read from /proc/<pid>/status, and
// stopped and reaped (SIGTERM, then SIGKILL) on every path out, failures
// included, all inside a temporary folder removed afterwards.
//
// Why a module of its own: none of this knows what is measured or tested.
// bench/memory.cpp holds only what is specific to mpmd (the plant and
// configuration it writes, the samples it feeds, the figures), the tests
// only their cases, and the subtle part here (what may run between fork and
// exec, the order of teardown) is read and tested once
// (tests/bench/test_child_process.cpp).
//
// Linux only (prctl, close_range, /proc), as the service it runs.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace mpm::test {

// A fresh folder `<temp>/<prefix>-XXXXXX` from mkdtemp under $TMPDIR (or
// /tmp), made on construction and removed with everything in it on
// destruction. Declare it before the ChildProcess and NotifySocket that use
// it, so it goes after them.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "mpm-test");
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  // False and `why` when mkdtemp failed (path() is then "").
  bool ok(std::string& why) const;
  const std::string& path() const { return path_; }
  // `<path>/<name>` ("<path>/" for an empty name).
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  // Writes `text` to file(name).
  void write(const std::string& name, const std::string& text) const;

 private:
  std::string path_;
  std::string error_;
};

// Writes `text` to `path` (replacing it); false when it could not.
bool write_text_file(const std::string& path, const std::string& text);

// The whole text of a file, "" if unreadable.
std::string read_text_file(const std::string& path);

// The last non-empty line of a file (a child's log), "" if none or unreadable.
std::string last_nonempty_line(const std::string& path);

// A regular file we may execute (what execve needs; a folder is not one).
bool is_executable_file(const std::string& path);

// Memory fields of /proc/<pid>/status in MB (1 MB = 2^20 bytes; the file
// gives kB), 0 for a field the kernel does not report.
struct ProcMemory {
  double vm_rss_mb = 0.0;    // VmRSS: resident now
  double vm_hwm_mb = 0.0;    // VmHWM: peak resident
  double rss_anon_mb = 0.0;  // RssAnon: heap and stacks
  double rss_file_mb = 0.0;  // RssFile: mapped files (executable, libraries)
};
// nullopt when the file cannot be read or has no VmRSS (a gone process, a zombie).
std::optional<ProcMemory> read_proc_memory(pid_t pid);

// A waitpid status in words: "exited with code N", "was killed by signal S".
std::string describe_exit(int wait_status);

// A child process started with fork/exec: stdin from /dev/null, stdout and
// stderr to log files (one or two), none of our other descriptors, and
// PR_SET_PDEATHSIG so it gets SIGTERM if we die before stopping it. stop()
// (or the destructor) sends SIGTERM, waits up to `stop_timeout`, then
// SIGKILL, and always reaps it: no zombie and no orphan is left on any path.
//
// The death signal is tied to the thread that forked (prctl(2)): start and
// stop it from a thread that outlives it, as the benches do (the main one).
class ChildProcess {
 public:
  explicit ChildProcess(std::chrono::milliseconds stop_timeout) : stop_timeout_(stop_timeout) {}
  // For tests: started at once with our environment plus `env`, stdout and
  // stderr to their files; killed at once (no grace) if still running at the
  // end. started() says whether it could be.
  ChildProcess(const std::vector<std::string>& args, std::string stdout_path, std::string stderr_path,
               const std::map<std::string, std::string>& env = {});
  ~ChildProcess() { stop(); }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Runs args[0] (a path: no PATH search) with `args` and exactly the
  // environment `env` ("NAME=value" entries). False and `why` when the log
  // cannot be opened or fork fails; a failed execve shows as exit code 127
  // and a line naming the program in the log. stderr goes to `stderr_log`
  // when one is given, else to `log` too.
  bool start(const std::vector<std::string>& args, const std::vector<std::string>& env, const std::string& log,
             std::string& why, const std::string& stderr_log = "");

  pid_t pid() const { return pid_; }
  bool started() const { return pid_ > 0; }
  void signal(int sig) const;

  // False once it has exited (then exit_status() holds the waitpid status),
  // or when it was never started. Reaps it when it has exited.
  bool running();
  std::optional<int> exit_status() const { return status_; }

  // The exit code (128 + signal when killed), or nothing while it still runs
  // after `timeout` (or was never started).
  std::optional<int> wait_exit(std::chrono::milliseconds timeout);

  // SIGTERM, up to stop_timeout for it to exit, then SIGKILL; always reaped.
  // Does nothing when it is not running.
  void stop();

  // What it wrote so far (the files given to the test constructor).
  std::string stdout_text() const { return read_text_file(stdout_path_); }
  std::string stderr_text() const { return read_text_file(stderr_path_); }
  static std::string read(const std::string& path) { return read_text_file(path); }

 private:
  std::chrono::milliseconds stop_timeout_;
  pid_t pid_ = -1;
  std::optional<int> status_;
  std::string stdout_path_;
  std::string stderr_path_;
};

// Our environment with `set` entries set (replacing ours) and every entry
// starting with one of `drop` left out.
std::vector<std::string> environment_with(const std::map<std::string, std::string>& set,
                                          const std::vector<std::string>& drop = {});

// Our environment for a child that should notify us: NOTIFY_SOCKET set to
// `socket_path`, and no WATCHDOG_* (a systemd watchdog of ours is not its).
std::vector<std::string> environment_with_notify_socket(const std::string& socket_path);

// The systemd side of sd_notify: a datagram socket bound to a path that the
// child finds in NOTIFY_SOCKET. The socket file is not unlinked: it lives in
// a TempDir, removed after this is closed.
class NotifySocket {
 public:
  NotifySocket() = default;
  ~NotifySocket();
  NotifySocket(const NotifySocket&) = delete;
  NotifySocket& operator=(const NotifySocket&) = delete;

  // False and `why` when the path is too long for sockaddr_un or bind fails.
  bool bind(const std::string& path, std::string& why);
  // Waits up to `wait` for one datagram; true when one came containing `needle`.
  bool receive(const char* needle, std::chrono::milliseconds wait);

 private:
  int fd_ = -1;
};

enum class ReadyWait {
  kReady,     // READY=1 came
  kExited,    // the child exited first (its exit_status() says how)
  kTimedOut,  // neither within the timeout; the child is still running
};
// Waits for the child's READY=1 on `notify`, checking between datagrams (and
// at least every 100 ms) that it is still alive.
ReadyWait wait_for_ready(NotifySocket& notify, ChildProcess& child, std::chrono::milliseconds timeout);

}  // namespace mpm::test
