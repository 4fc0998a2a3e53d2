// lcm-spy shows our messages decoded: with mpmd raising alarms, lcm-spy (run
// by deploy/mpm-lcm-spy under Xvfb, wrapped by SpyProbe which prints what its
// windows show) lists MPM_ALARM with our type and no undecodable message; a
// double-click (xdotool) opens the decoded alarm, and a screenshot of it is
// saved as <build>/Testing/lcm-spy-alarm.png for people to look at. The
// diagnosis that follows the raise (diagnosis_t on MPM_DIAGNOSIS) is decoded
// too, and its viewer saved as <build>/Testing/lcm-spy-diagnosis.png.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>

#include "child_process.hpp"
#include "observer.hpp"
#include "transport/transport.hpp"
#include "wood_berry_stream.hpp"

namespace mpm::test {
namespace {

const std::string kMpmd = MPM_BINARY_DIR "/daemon/mpmd/mpmd";
const std::string kSpyScript = MPM_SOURCE_DIR "/deploy/mpm-lcm-spy";
const std::string kScreenshot = MPM_BINARY_DIR "/Testing/lcm-spy-alarm.png";
const std::string kDiagnosisScreenshot = MPM_BINARY_DIR "/Testing/lcm-spy-diagnosis.png";

bool on_path(const std::string& tool) { return std::system(("command -v " + tool + " >/dev/null 2>&1").c_str()) == 0; }

// One row of lcm-spy's channel table, from the probe's latest report.
struct Row {
  std::string channel, type;
  long messages = 0, undecodable = 0;
  int x = 0, y = 0;
};

// The last complete report of the probe ("... end").
std::vector<std::string> last_report(const std::string& out) {
  std::vector<std::string> lines, report;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    if (line == "end") {
      report = lines;
      lines.clear();
    } else {
      lines.push_back(line);
    }
  }
  return report;
}

std::optional<Row> row(const std::string& out, const std::string& channel) {
  for (const auto& line : last_report(out)) {
    std::istringstream f(line);
    std::string kind;
    Row r;
    std::getline(f, kind, '\t');
    if (kind != "row") continue;
    std::string messages, undecodable, x, y;
    std::getline(f, r.channel, '\t');
    std::getline(f, r.type, '\t');
    std::getline(f, messages, '\t');
    std::getline(f, undecodable, '\t');
    std::getline(f, x, '\t');
    std::getline(f, y, '\t');
    if (r.channel != channel) continue;
    r.messages = std::stol(messages);
    r.undecodable = std::stol(undecodable);
    r.x = std::stoi(x);
    r.y = std::stoi(y);
    return r;
  }
  return std::nullopt;
}

bool viewer_open(const std::string& out, const std::string& channel) {
  for (const auto& line : last_report(out)) {
    if (line.rfind("viewer\t" + channel + "\t", 0) == 0) return true;
  }
  return false;
}

// lcm-spy's row of `channel` once the probe reports it.
std::optional<Row> wait_row(const ChildProcess& spy, const std::string& channel) {
  if (!eventually([&] { return row(spy.stdout_text(), channel).has_value(); })) return std::nullopt;
  return row(spy.stdout_text(), channel);
}

// Decoded by lcm-spy as our `type`, nothing undecodable.
void expect_decoded(const Row& r, const std::string& type) {
  EXPECT_EQ(r.type, type) << r.channel;
  EXPECT_EQ(r.undecodable, 0) << r.channel;
}

// Double-clicks `r` in lcm-spy's channel table (on `display`) until its viewer opens.
bool open_viewer(const std::string& display, const ChildProcess& spy, const Row& r) {
  const std::string click = "DISPLAY=" + display + " xdotool mousemove " + std::to_string(r.x) + " " +
                            std::to_string(r.y) + " click --repeat 2 --delay 100 1";
  return eventually([&] {
    if (std::system(click.c_str()) != 0) return false;
    return eventually([&] { return viewer_open(spy.stdout_text(), r.channel); }, std::chrono::seconds(3));
  });
}

// A picture of the whole screen in `path`. The viewer paints its fields after
// opening; the probe saw its panel, the picture is kept once it has been on
// screen for a report or two.
bool screenshot(const std::string& display, const std::string& path) {
  std::filesystem::create_directories(MPM_BINARY_DIR "/Testing");
  std::filesystem::remove(path);
  return eventually([&] {
    return std::system(("DISPLAY=" + display + " import -window root " + path).c_str()) == 0 &&
           std::filesystem::file_size(path) > 10000;
  });
}

TEST(LcmSpy, ShowsOurAlarmsDecoded) {
  for (const char* tool : {"Xvfb", "xdotool", "import", "java"}) {
    ASSERT_TRUE(on_path(tool)) << tool << " is missing: apt-get install -y xvfb xdotool imagemagick "
                                          "openjdk-17-jdk-headless libjchart2d-java";
  }
  ASSERT_TRUE(std::filesystem::exists("/usr/share/java/jchart2d.jar")) << "apt-get install -y libjchart2d-java";
  ASSERT_TRUE(std::filesystem::exists(MPM_LCM_TYPES_JAR)) << "the type jar was not built";
  TempDir dir;

  // A display of our own.
  const std::string display = ":" + std::to_string(100 + ::getpid() % 400);
  ChildProcess xvfb({"/usr/bin/Xvfb", display, "-screen", "0", "1280x800x24", "-nolisten", "tcp"},
                    dir.file("xvfb.out"), dir.file("xvfb.err"));
  ASSERT_TRUE(eventually([&] { return std::filesystem::exists("/tmp/.X11-unix/X" + display.substr(1)); }))
      << xvfb.stderr_text();

  transport::Settings settings;
  settings.lcm.url = "udpm://239.255.76.69:" + std::to_string(21000 + ::getpid() % 1000) + "?ttl=0";
  dir.write("mpmd.yaml", "controller_id: wb\nplant: " MPM_SOURCE_DIR "/config/wood-berry.yaml\n"
                         "monitor: {ar_order: 5, input_order: 10, forgetting: 0.995, false_alarm: 1.0e-5,\n"
                         "          settle_samples: 100}\n"
                         "transport: {kind: lcm, lcm: {url: \"" + settings.lcm.url + "\"}}\n"
                         "status_period: 0.1\n");
  ChildProcess mpmd({kMpmd, "--config", dir.file("mpmd.yaml")}, dir.file("mpmd.out"), dir.file("mpmd.err"));
  std::string error;
  auto t = transport::create(settings, error);
  ASSERT_TRUE(t) << error;
  Observer obs(*t);
  ASSERT_TRUE(obs.wait_status("wb", [](const msg::Status&) { return true; })) << mpmd.stderr_text();

  // lcm-spy through our launcher, wrapped by the probe.
  ChildProcess spy({"/bin/sh", kSpyScript, "--lcm-url=" + settings.lcm.url}, dir.file("spy.out"),
                   dir.file("spy.err"),
                   {{"DISPLAY", display},
                    {"MPM_LCM_TYPES_JAR", MPM_LCM_TYPES_JAR},
                    {"MPM_LCM_SPY_MAIN", "SpyProbe"},
                    {"MPM_LCM_SPY_EXTRA_CLASSPATH", MPM_SPY_PROBE_JAR}});
  ASSERT_TRUE(eventually([&] { return row(spy.stdout_text(), "MPM_STATUS").has_value(); }, std::chrono::seconds(60)))
      << spy.stdout_text() << spy.stderr_text();
  EXPECT_NE(spy.stdout_text().find("Found 6 LCM types"), std::string::npos) << "lcm-spy loaded our jar";

  // Alarms flow: the controller's plant drifts until mpmd raises.
  WoodBerryStream stream(3);
  msg::Sample s;
  s.controller_id = "wb";
  s.session_id = 9;
  for (int k = 0; k < 4000 && obs.alarms().empty(); ++k) {
    if (k == 600) stream.set_g21_gain(1.5);
    stream.next(s);
    s.seq = k + 1;
    ASSERT_TRUE(t->publish(s));
    if (k % 50 == 49) {
      const std::int64_t sent = k + 1;
      ASSERT_TRUE(obs.wait_status("wb", [&](const msg::Status& st) { return st.samples_seen >= sent; }));
    }
  }
  ASSERT_TRUE(obs.wait_alarms([](const auto& a) { return !a.empty(); }, std::chrono::seconds(10)));

  // lcm-spy decoded it: our type name, nothing undecodable.
  const std::optional<Row> alarm = wait_row(spy, "MPM_ALARM");
  ASSERT_TRUE(alarm) << spy.stdout_text();
  expect_decoded(*alarm, "alarm_t");
  EXPECT_GE(alarm->messages, 1);
  expect_decoded(*row(spy.stdout_text(), "MPM_STATUS"), "status_t");
  expect_decoded(*row(spy.stdout_text(), "MPM_SAMPLE"), "sample_t");

  // Open the alarm's viewer as an operator would, and keep a picture of it.
  ASSERT_TRUE(open_viewer(display, spy, *alarm)) << spy.stdout_text();
  ASSERT_TRUE(screenshot(display, kScreenshot));
  std::printf("screenshot: %s\n", kScreenshot.c_str());

  // The diagnosis that follows the raise: decoded as diagnosis_t.
  ASSERT_TRUE(eventually([&] { return !obs.diagnoses().empty(); })) << mpmd.stderr_text();
  const std::optional<Row> diagnosis = wait_row(spy, "MPM_DIAGNOSIS");
  ASSERT_TRUE(diagnosis) << spy.stdout_text();
  expect_decoded(*diagnosis, "diagnosis_t");
  EXPECT_GE(diagnosis->messages, 1);
  // The alarm's viewer opened over the channel table (no window manager
  // here): hide it so the double-click reaches the table.
  std::system(("DISPLAY=" + display + " xdotool search --name '^MPM_ALARM$' windowunmap >/dev/null 2>&1").c_str());
  ASSERT_TRUE(open_viewer(display, spy, *diagnosis)) << spy.stdout_text();
  ASSERT_TRUE(screenshot(display, kDiagnosisScreenshot));
  std::printf("screenshot: %s (%s)\n", kDiagnosisScreenshot.c_str(), obs.diagnoses().front().text.c_str());

  spy.signal(SIGTERM);
  spy.wait_exit(std::chrono::seconds(10));
  mpmd.signal(SIGTERM);
  EXPECT_EQ(mpmd.wait_exit(std::chrono::seconds(20)), 0);
  xvfb.signal(SIGTERM);
}

}  // namespace
}  // namespace mpm::test
