#include "bench/memory.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "bench/workload.hpp"

namespace mpm::bench {

double status_field_mb(const char* field) {
  std::ifstream in("/proc/self/status");
  std::string line;
  const std::size_t len = std::strlen(field);
  while (std::getline(in, line)) {
    if (line.compare(0, len, field) == 0 && line.size() > len && line[len] == ':')
      return std::stod(line.substr(len + 1)) / 1024.0;  // the file says kB
  }
  return 0.0;
}

namespace {

// In the child: build, run, measure, write three doubles, exit.
[[noreturn]] void child_measure(int fd, std::size_t inputs, std::size_t outputs) {
  ResidentMemory m;
  m.baseline_mb = status_field_mb("VmRSS");
  {
    const Workload w = make_workload(inputs, outputs, 64);
    auto monitor = make_monitor(inputs, outputs);
    std::size_t k = warm_up(*monitor, w, 0);
    for (int i = 0; i < 2; ++i, ++k) monitor->update(w.u_at(k), w.residual_at(k));
    m.rss_mb = status_field_mb("VmRSS");
    m.hwm_mb = status_field_mb("VmHWM");
  }
  const ssize_t written = write(fd, &m, sizeof m);
  _exit(written == static_cast<ssize_t>(sizeof m) ? 0 : 1);
}

}  // namespace

std::optional<ResidentMemory> measure_monitor_memory(std::size_t inputs, std::size_t outputs, std::string& why) {
  int fds[2];
  if (pipe(fds) != 0) {
    why = std::string("pipe failed: ") + std::strerror(errno);
    return std::nullopt;
  }
  std::fflush(nullptr);  // the child must not flush our buffered output again
  const pid_t pid = fork();
  if (pid < 0) {
    why = std::string("fork failed: ") + std::strerror(errno);
    close(fds[0]);
    close(fds[1]);
    return std::nullopt;
  }
  if (pid == 0) {
    close(fds[0]);
    child_measure(fds[1], inputs, outputs);
  }
  close(fds[1]);
  ResidentMemory m;
  const ssize_t got = read(fds[0], &m, sizeof m);
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (got != static_cast<ssize_t>(sizeof m) || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    why = "the measuring child process failed";
    return std::nullopt;
  }
  return m;
}

}  // namespace mpm::bench
