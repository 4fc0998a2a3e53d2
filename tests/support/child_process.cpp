#include "support/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <thread>

extern char** environ;

namespace mpm::test {

namespace fs = std::filesystem;

using Clock = std::chrono::steady_clock;

TempDir::TempDir(const std::string& prefix) {
  std::error_code ec;
  const fs::path base = fs::temp_directory_path(ec);  // $TMPDIR when set
  std::string pattern = ((ec ? fs::path("/tmp") : base) / (prefix + "-XXXXXX")).string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    error_ = "mkdtemp(" + pattern + ") failed: " + std::strerror(errno);
  } else {
    path_ = pattern;
  }
}

TempDir::~TempDir() {
  std::error_code ec;
  if (!path_.empty()) fs::remove_all(path_, ec);
}

bool TempDir::ok(std::string& why) const {
  if (path_.empty()) why = error_;
  return !path_.empty();
}

void TempDir::write(const std::string& name, const std::string& text) const { write_text_file(file(name), text); }

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

bool write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  return static_cast<bool>(out);
}

std::string last_nonempty_line(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

bool is_executable_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(path.c_str(), X_OK) == 0;
}

std::optional<ProcMemory> read_proc_memory(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  if (!in) return std::nullopt;
  ProcMemory m;
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    const std::string key = line.substr(0, colon);
    double* field = key == "VmRSS"     ? &m.vm_rss_mb
                    : key == "VmHWM"   ? &m.vm_hwm_mb
                    : key == "RssAnon" ? &m.rss_anon_mb
                    : key == "RssFile" ? &m.rss_file_mb
                                       : nullptr;
    if (field) *field = std::strtod(line.c_str() + colon + 1, nullptr) / 1024.0;  // "  1234 kB"
  }
  if (m.vm_rss_mb <= 0.0) return std::nullopt;
  return m;
}

std::string describe_exit(int wait_status) {
  if (WIFEXITED(wait_status)) return "exited with code " + std::to_string(WEXITSTATUS(wait_status));
  if (WIFSIGNALED(wait_status)) return std::string("was killed by signal ") + strsignal(WTERMSIG(wait_status));
  return "stopped";
}

// ---------------------------------------------------------------------------
// ChildProcess

ChildProcess::ChildProcess(const std::vector<std::string>& args, std::string stdout_path, std::string stderr_path,
                           const std::map<std::string, std::string>& env)
    : stop_timeout_(0), stdout_path_(std::move(stdout_path)), stderr_path_(std::move(stderr_path)) {
  std::string why;
  start(args, environment_with(env), stdout_path_, why, stderr_path_);
}

bool ChildProcess::start(const std::vector<std::string>& args, const std::vector<std::string>& env,
                         const std::string& log, std::string& why, const std::string& stderr_log) {
  // Everything the child needs is made before fork: between fork and exec
  // only async-signal-safe calls (no allocation: another thread of ours may
  // have held the allocator's lock when we forked).
  std::vector<char*> argv, envp;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  for (const auto& e : env) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);
  // "<3>" is the error level of the sd-daemon log prefix the services use.
  const std::string exec_failed =
      "<3>execve of " + fs::path(args.empty() ? std::string() : args[0]).filename().string() + " failed\n";
  const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int err = stderr_log.empty() ? out : ::open(stderr_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int in = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  const auto close_all = [&] {
    if (out >= 0) ::close(out);
    if (err >= 0 && err != out) ::close(err);
    if (in >= 0) ::close(in);
  };
  if (out < 0 || err < 0 || in < 0) {
    why = "cannot open " + log + (stderr_log.empty() ? "" : ", " + stderr_log) + " or /dev/null: " + std::strerror(errno);
    close_all();
    return false;
  }
  const pid_t parent = ::getpid();
  std::fflush(nullptr);  // or buffered output of ours would be written twice
  pid_ = ::fork();
  if (pid_ == 0) {
    // Dies with us even if we are killed before stopping it; and if we
    // already died between fork and prctl, the signal will never come.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(126);
    ::dup2(in, 0);
    ::dup2(out, 1);
    ::dup2(err, 2);
    // No descriptor of ours (sockets above all, not all opened O_CLOEXEC by
    // the libraries that own them) in the child.
    ::close_range(3, ~0U, 0);
    ::execve(argv[0], argv.data(), envp.data());
    [[maybe_unused]] const ssize_t n = ::write(2, exec_failed.data(), exec_failed.size());
    ::_exit(127);
  }
  const int fork_errno = errno;
  close_all();
  if (pid_ < 0) {
    why = std::string("fork failed: ") + std::strerror(fork_errno);
    return false;
  }
  return true;
}

bool ChildProcess::running() {
  if (pid_ <= 0 || status_) return false;
  int status = 0;
  if (::waitpid(pid_, &status, WNOHANG) == pid_) {
    status_ = status;
    return false;
  }
  return true;
}

void ChildProcess::signal(int sig) const {
  if (pid_ > 0 && !status_) ::kill(pid_, sig);
}

std::optional<int> ChildProcess::wait_exit(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (running()) {
    if (Clock::now() >= deadline) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!status_) return std::nullopt;
  return WIFEXITED(*status_) ? WEXITSTATUS(*status_) : 128 + WTERMSIG(*status_);
}

void ChildProcess::stop() {
  if (!running()) return;
  ::kill(pid_, SIGTERM);
  const auto deadline = Clock::now() + stop_timeout_;
  while (running() && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  if (!running()) return;
  ::kill(pid_, SIGKILL);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  status_ = status;
}

// ---------------------------------------------------------------------------
// sd_notify

std::vector<std::string> environment_with(const std::map<std::string, std::string>& set,
                                          const std::vector<std::string>& drop) {
  std::vector<std::string> env;
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    const std::string entry = *e;
    const std::string name = entry.substr(0, entry.find('='));
    const bool dropped = std::any_of(drop.begin(), drop.end(), [&](const std::string& p) { return entry.rfind(p, 0) == 0; });
    if (!dropped && !set.count(name)) env.push_back(entry);
  }
  for (const auto& [name, value] : set) env.push_back(name + "=" + value);
  return env;
}

std::vector<std::string> environment_with_notify_socket(const std::string& socket_path) {
  return environment_with({{"NOTIFY_SOCKET", socket_path}}, {"WATCHDOG_"});
}

NotifySocket::~NotifySocket() {
  if (fd_ >= 0) ::close(fd_);
}

bool NotifySocket::bind(const std::string& path, std::string& why) {
  sockaddr_un addr{};
  if (path.size() >= sizeof addr.sun_path) {
    why = "notify socket path too long: " + path;
    return false;
  }
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  addr.sun_family = AF_UNIX;
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
  if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    why = "cannot bind the notify socket " + path + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

bool NotifySocket::receive(const char* needle, std::chrono::milliseconds wait) {
  pollfd p{fd_, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(wait.count())) <= 0) return false;
  char buf[1024];
  const ssize_t n = ::recv(fd_, buf, sizeof buf - 1, MSG_DONTWAIT);
  if (n <= 0) return false;
  buf[n] = '\0';
  return std::strstr(buf, needle) != nullptr;
}

ReadyWait wait_for_ready(NotifySocket& notify, ChildProcess& child, std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    if (notify.receive("READY=1", std::chrono::milliseconds(100))) return ReadyWait::kReady;
    if (!child.running()) return ReadyWait::kExited;
  }
  return ReadyWait::kTimedOut;
}

}  // namespace mpm::test
