// The mpmd memory figures of `mpm bench` (bench/memory.hpp): the plant it
// writes loads, mpmd is found where it is installed or built (or where
// MPM_MPMD says), the real mpmd is measured after its monitor used samples,
// and on every path (success, a crashing mpmd, a silent one) no child process
// and no temporary file is left behind. No figure's size is asserted.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "bench/memory.hpp"
#include "config/plant_loader.hpp"

namespace mpm::bench {
namespace {

namespace fs = std::filesystem;

// A fresh folder, set as TMPDIR while the test runs (the measurement makes
// its own folder in it), removed afterwards.
class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (fs::temp_directory_path() / "mpm-bench-test-XXXXXX").string();
    if (::mkdtemp(pattern.data()) != nullptr) path_ = pattern;
    if (const char* t = std::getenv("TMPDIR")) old_tmpdir_ = t;
    ::setenv("TMPDIR", path_.c_str(), 1);
  }
  ~ScratchDir() {
    if (old_tmpdir_) {
      ::setenv("TMPDIR", old_tmpdir_->c_str(), 1);
    } else {
      ::unsetenv("TMPDIR");
    }
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const std::string& path() const { return path_; }
  bool empty() const { return fs::is_empty(path_); }
  // An executable shell script `name` with `body` after the #! line.
  std::string script(const std::string& name, const std::string& body) const {
    const std::string file = path_ + "/" + name;
    std::ofstream(file) << "#!/bin/sh\n" << body;
    ::chmod(file.c_str(), 0755);
    return file;
  }

 private:
  std::string path_;
  std::optional<std::string> old_tmpdir_;
};

// No child of this process, running or exited but not reaped.
bool no_child_left() { return ::waitpid(-1, nullptr, WNOHANG) == -1 && errno == ECHILD; }

class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) { ::setenv(name, value.c_str(), 1); }
  ~ScopedEnv() { ::unsetenv(name_); }

 private:
  const char* name_;
};

TEST(BenchPlant, LoadsWithEveryChannelAndNoiseModel) {
  for (const std::size_t n : {std::size_t{2}, std::size_t{50}}) {
    SCOPED_TRACE(n);
    const PlantModel p = config::parse_plant(bench_plant_yaml(n), "bench plant");
    EXPECT_EQ(p.n_inputs(), n);
    EXPECT_EQ(p.n_outputs(), n);
    EXPECT_EQ(p.channels.size(), n * n);
    ASSERT_EQ(p.noise.size(), n);
    for (const auto& noise : p.noise) EXPECT_TRUE(noise.has_value()) << "gamma needs a noise model everywhere";
    ASSERT_TRUE(p.operating_point.has_value());
    EXPECT_EQ(p.operating_point->inputs.size(), n);
  }
  EXPECT_EQ(config::parse_plant(bench_plant_yaml(2), "wb").name, "wood-berry");
}

TEST(FindMpmd, InstalledLayoutBesideMpmAndNotAPlainFile) {
  ::unsetenv("MPM_MPMD");
  ScratchDir dir;
  std::string why;
  EXPECT_FALSE(find_mpmd(dir.path(), why));
  EXPECT_NE(why.find(dir.path() + "/mpmd/mpmd"), std::string::npos) << why;

  std::ofstream(dir.path() + "/mpmd") << "not executable\n";
  EXPECT_FALSE(find_mpmd(dir.path(), why)) << "a file without the execute bit is not mpmd";
  ::chmod((dir.path() + "/mpmd").c_str(), 0755);
  const auto found = find_mpmd(dir.path(), why);
  ASSERT_TRUE(found) << why;
  EXPECT_EQ(*found, dir.path() + "/mpmd");
}

TEST(FindMpmd, EnvironmentOverrideWinsAndIsChecked) {
  ScratchDir dir;
  const std::string fake = dir.script("my-mpmd", "exit 0\n");
  std::string why;
  {
    ScopedEnv env("MPM_MPMD", fake);
    const auto found = find_mpmd("/nonexistent", why);
    ASSERT_TRUE(found) << why;
    EXPECT_EQ(*found, fake);
  }
  {
    ScopedEnv env("MPM_MPMD", dir.path() + "/missing");
    EXPECT_FALSE(find_mpmd(dir.path(), why));
    EXPECT_NE(why.find("MPM_MPMD"), std::string::npos) << why;
  }
}

#ifdef MPM_MPMD_EXE

TEST(FindMpmd, BuildTreeLayout) {
  ::unsetenv("MPM_MPMD");
  const fs::path daemon_dir = fs::path(MPM_MPMD_EXE).parent_path().parent_path();  // build/daemon
  std::string why;
  const auto found = find_mpmd(daemon_dir.string(), why);
  ASSERT_TRUE(found) << why;
  EXPECT_TRUE(fs::equivalent(*found, MPM_MPMD_EXE));
}

TEST(MeasureMpmd, TheRealServiceAfterItsMonitorUsedSamplesLeavesNothingBehind) {
  ScratchDir dir;
  MpmdRun run;
  run.mpmd = MPM_MPMD_EXE;
  run.n = 2;
  run.used = 50;
  std::string why;
  const auto m = measure_mpmd_memory(run, why);
  ASSERT_TRUE(m) << why;
  EXPECT_GT(m->rss_mb, 0.0);
  EXPECT_GE(m->hwm_mb, m->rss_mb);
  EXPECT_GT(m->anon_mb, 0.0);
  EXPECT_GE(m->samples_used, 50u);
  EXPECT_EQ(m->samples_seen, m->samples_sent) << "every sample sent was processed before measuring";
  EXPECT_GT(m->samples_sent, m->samples_used) << "the first samples only fill the lags";
  EXPECT_TRUE(no_child_left());
  EXPECT_EQ(::kill(m->pid, 0), -1) << "mpmd still exists";
  EXPECT_TRUE(dir.empty()) << "temporary files left in " << dir.path();
}

#endif

TEST(MeasureMpmd, AnMpmdThatFailsIsReportedWithItsLastLogLine) {
  ScratchDir dir;
  MpmdRun run;
  run.mpmd = dir.script("failing-mpmd", "echo '<6>starting' >&2\necho '<3>broken on purpose' >&2\nexit 3\n");
  std::string why;
  EXPECT_FALSE(measure_mpmd_memory(run, why));
#ifdef MPM_BENCH_HAVE_TRANSPORT
  EXPECT_NE(why.find("exited with code 3"), std::string::npos) << why;
  EXPECT_NE(why.find("broken on purpose"), std::string::npos) << why;
#endif
  EXPECT_FALSE(why.empty());
  EXPECT_TRUE(no_child_left());
  fs::remove(run.mpmd);
  EXPECT_TRUE(dir.empty()) << "temporary files left in " << dir.path();
}

TEST(MeasureMpmd, AnMpmdThatNeverGetsReadyAndIgnoresSigtermIsKilled) {
  ScratchDir dir;
  MpmdRun run;
  run.mpmd = dir.script("silent-mpmd", "trap '' TERM\nwhile :; do sleep 0.05; done\n");
  run.ready_timeout = std::chrono::milliseconds(300);
  run.stop_timeout = std::chrono::milliseconds(300);
  std::string why;
  EXPECT_FALSE(measure_mpmd_memory(run, why));
#ifdef MPM_BENCH_HAVE_TRANSPORT
  EXPECT_NE(why.find("no READY=1"), std::string::npos) << why;
#endif
  EXPECT_TRUE(no_child_left());
  fs::remove(run.mpmd);
  EXPECT_TRUE(dir.empty()) << "temporary files left in " << dir.path();
}

}  // namespace
}  // namespace mpm::bench
