// The GRBL stage driver against the GRBL 1.1 emulator on a pseudo-terminal: connecting, moves
// that take their time, GRBL's errors and alarms in the messages, homing, a silent controller,
// ports that are not ttys, and the stop signal halting the stage.
#include "acquire/devices/grbl_stage.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>

#include "acquire/devices/serial_port.h"
#include "core/error.h"
#include "core/stop_signal.h"
#include "grbl_emulator.h"

namespace lumislab {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

StageSettings TestSettings() {
  StageSettings settings;
  settings.feed_mm_min = 3000;  // 50 mm/s
  settings.reply_timeout_s = 0.5;
  settings.move_timeout_s = 10;
  return settings;
}

std::string Uri(const GrblEmulator& emulator) { return "grbl:" + emulator.SlavePath(); }

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/grbl_" + std::to_string(::getpid()) + "_" + name;
}

std::string FileText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The error `body` throws (a test failure when it throws none).
Error Thrown(const std::function<void()>& body) {
  try {
    body();
  } catch (const Error& error) {
    return error;
  }
  ADD_FAILURE() << "no error thrown";
  return Failure("none");
}

bool HasEvent(const GrblEmulator& emulator, const std::string& text) {
  for (const auto& event : emulator.Events()) {
    if (event.text == text) return true;
  }
  return false;
}

TEST(GrblStage, ConnectsMovesAndReadsBack) {
  GrblEmulator emulator;
  const std::string log_path = TempPath("move.log");
  std::remove(log_path.c_str());
  {
    DeviceLog log(log_path);
    GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
    stage.Connect(TestSettings(), &log);
    const auto start = Clock::now();
    const AxisTargets at = stage.MoveTo({{'X', 10}, {'Y', 20}});
    // 22.4 mm at 50 mm/s with 500 mm/s^2 ramps: the move takes its time.
    EXPECT_GT(Since(start), 0.4);
    EXPECT_LT(Since(start), 2.0);
    ASSERT_EQ(at.size(), 2u);
    EXPECT_EQ(at[0].first, 'X');
    EXPECT_NEAR(at[0].second, 10, 0.001);
    EXPECT_EQ(at[1].first, 'Y');
    EXPECT_NEAR(at[1].second, 20, 0.001);
    const auto position = emulator.Position();
    EXPECT_NEAR(position[0], 10, 1e-9);
    EXPECT_NEAR(position[1], 20, 1e-9);
    EXPECT_NEAR(position[2], 0, 1e-9);
    // A second move, relative to the first.
    const AxisTargets back = stage.MoveTo({{'Z', 5}});
    EXPECT_NEAR(back[0].second, 5, 0.001);
    stage.Close();
  }
  EXPECT_TRUE(HasEvent(emulator, "state Run"));
  EXPECT_TRUE(HasEvent(emulator, "> G1 X10.000 Y20.000 F3000"));
  const std::string log = FileText(log_path);
  for (const char* line :
       {"> <0x18>", "< Grbl 1.1h ['$' for help]", "> G21 G90", "< ok", "> G1 X10.000 Y20.000 F3000",
        "< <Run|MPos:", "< <Idle|MPos:", "# at X=10 Y=20", "> G1 Z5.000 F3000", "# closed"}) {
    EXPECT_NE(log.find(line), std::string::npos) << line << " not in\n" << log;
  }
  EXPECT_NE(log.find(" grbl:" + emulator.SlavePath() + " > G21 G90\n"), std::string::npos);
}

TEST(GrblStage, ReadsWorkPositionWithEitherReport) {
  for (const bool wpos : {false, true}) {
    GrblEmulatorOptions options;
    options.speed_factor = 4;
    options.wco_mm = {5, 7, 0};
    options.report_wpos = wpos;
    GrblEmulator emulator(options);
    GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
    stage.Connect(TestSettings(), nullptr);
    const AxisTargets at = stage.MoveTo({{'X', 10}, {'Y', 1}});
    EXPECT_NEAR(at[0].second, 10, 0.001) << wpos;
    EXPECT_NEAR(at[1].second, 1, 0.001) << wpos;
    const auto machine = emulator.Position();
    EXPECT_NEAR(machine[0], 15, 1e-9);
    EXPECT_NEAR(machine[1], 8, 1e-9);
  }
}

TEST(GrblStage, ErrorReplyNamesGrblsText) {
  GrblEmulator emulator;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  stage.Connect(TestSettings(), nullptr);
  emulator.RequireHoming(true);  // the alarm lock refuses G-code with error:9
  const Error error = Thrown([&] { stage.MoveTo({{'X', 10}}); });
  EXPECT_EQ(error.exit_code(), 1);
  EXPECT_EQ(std::string(error.what()),
            Uri(emulator) + ": moving to X=10: 'G1 X10.000 F3000' answered error:9 G-code lock " +
                "(G-code is locked out in the alarm or jog state)");
}

TEST(GrblStage, RefusesAxesGrblDoesNotHave) {
  GrblEmulator emulator;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  stage.Connect(TestSettings(), nullptr);
  const Error unknown = Thrown([&] { stage.MoveTo({{'Q', 1}}); });
  EXPECT_EQ(unknown.exit_code(), 2);
  EXPECT_NE(std::string(unknown.what()).find("'Q' is not a GRBL axis (X Y Z A B C)"),
            std::string::npos)
      << unknown.what();
  const Error missing = Thrown([&] { stage.MoveTo({{'A', 1}}); });
  EXPECT_NE(std::string(missing.what()).find("the controller has 3 axes, no A"), std::string::npos)
      << missing.what();
}

TEST(GrblStage, AlarmMidMoveNamesGrblsText) {
  GrblEmulator emulator;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  stage.Connect(TestSettings(), nullptr);
  std::thread alarm([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    emulator.InjectAlarm(1);
  });
  const auto start = Clock::now();
  const Error error = Thrown([&] { stage.MoveTo({{'X', 200}}); });
  alarm.join();
  EXPECT_LT(Since(start), 1.0);
  EXPECT_EQ(error.exit_code(), 1);
  EXPECT_EQ(std::string(error.what()),
            Uri(emulator) +
                ": moving to X=200: ALARM:1 hard limit (a limit switch triggered; position "
                "lost, home again)");
  const double x = emulator.Position()[0];
  EXPECT_GT(x, 1);
  EXPECT_LT(x, 100);
  stage.Close();  // soft reset out of the critical alarm; never throws
}

TEST(GrblStage, SoftLimitIsAnAlarm) {
  GrblEmulator emulator;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  stage.Connect(TestSettings(), nullptr);
  const Error error = Thrown([&] { stage.MoveTo({{'X', 10}, {'Y', 400}}); });
  EXPECT_EQ(error.exit_code(), 1);
  EXPECT_EQ(std::string(error.what()),
            Uri(emulator) +
                ": moving to X=10 Y=400: ALARM:2 soft limit (motion target exceeds machine "
                "travel)");
  EXPECT_EQ(emulator.Position()[1], 0);  // nothing moved
  EXPECT_EQ(emulator.State(), "Alarm");
}

TEST(GrblStage, AlarmLockAtConnectNeedsHoming) {
  GrblEmulatorOptions options;
  options.require_homing = true;
  options.start_mm = {40, 30, 0};
  options.home_mm = {0, 0, 0};
  options.homing_s = 0.3;
  GrblEmulator emulator(options);
  {
    GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
    const Error error = Thrown([&] { stage.Connect(TestSettings(), nullptr); });
    EXPECT_EQ(error.exit_code(), 2);
    const std::string text = error.what();
    EXPECT_EQ(text.rfind(Uri(emulator) + ": connecting: the controller is in alarm", 0), 0u)
        << text;
    EXPECT_NE(text.find("\"home\": true"), std::string::npos) << text;
    EXPECT_NE(text.find("$X"), std::string::npos) << text;
  }
  StageSettings settings = TestSettings();
  settings.home = true;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  stage.Connect(settings, nullptr);
  const auto start = Clock::now();
  stage.Home();
  EXPECT_GT(Since(start), 0.25);  // homing takes its time
  EXPECT_TRUE(HasEvent(emulator, "> $H"));
  EXPECT_EQ(emulator.Position()[0], 0);
  const AxisTargets at = stage.MoveTo({{'X', 3}});
  EXPECT_NEAR(at[0].second, 3, 0.001);
}

TEST(GrblStage, SilentControllerAtConnectIsBadInput) {
  GrblEmulator emulator;
  emulator.SetSilent(true);
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  const auto start = Clock::now();
  const Error error = Thrown([&] { stage.Connect(TestSettings(), nullptr); });
  EXPECT_LT(Since(start), 0.5 + 0.3);
  EXPECT_GE(Since(start), 0.5);
  EXPECT_EQ(error.exit_code(), 2);
  EXPECT_EQ(std::string(error.what()),
            Uri(emulator) +
                ": connecting: no answer to a soft reset (Ctrl-X) within 0.5 s: is a "
                "GRBL controller on " +
                emulator.SlavePath() + " at 115200 baud?");
}

TEST(GrblStage, SilentControllerMidMoveIsDeviceError) {
  GrblEmulator emulator;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  stage.Connect(TestSettings(), nullptr);
  std::thread mute([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    emulator.SetSilent(true);
  });
  const auto start = Clock::now();
  const Error error = Thrown([&] { stage.MoveTo({{'X', 100}}); });
  mute.join();
  EXPECT_LT(Since(start), 0.3 + 0.1 + 0.5 + 0.3);
  EXPECT_EQ(error.exit_code(), 1);
  EXPECT_EQ(std::string(error.what()),
            Uri(emulator) + ": moving to X=100: no reply to '?' within 0.5 s");
  const auto close_start = Clock::now();
  stage.Close();  // halts blind: feed hold and reset into the silence
  EXPECT_LT(Since(close_start), 1.5);
}

TEST(GrblStage, RefusesPathsThatAreNotTtys) {
  const std::string file = TempPath("regular");
  std::ofstream(file) << "not a port\n";
  const std::string fifo = TempPath("fifo");
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  for (const std::string& path : {file, fifo, std::string("/dev/null")}) {
    GrblStage stage("grbl:" + path, path, 115200);
    const Error error = Thrown([&] { stage.Connect(TestSettings(), nullptr); });
    EXPECT_EQ(error.exit_code(), 2);
    EXPECT_EQ(std::string(error.what()),
              "grbl:" + path + ": " + path + " is not a serial port (tty)");
  }
  const std::string missing = TempPath("no_such_port");
  GrblStage stage("grbl:" + missing, missing, 115200);
  const Error error = Thrown([&] { stage.Connect(TestSettings(), nullptr); });
  EXPECT_EQ(error.exit_code(), 2);
  EXPECT_EQ(std::string(error.what()),
            "grbl:" + missing + ": " + missing + ": no such serial port");
  GrblEmulator emulator;
  GrblStage odd_baud(Uri(emulator), emulator.SlavePath(), 12345);
  const Error baud = Thrown([&] { odd_baud.Connect(TestSettings(), nullptr); });
  EXPECT_EQ(baud.exit_code(), 2);
  EXPECT_NE(std::string(baud.what()).find("baud 12345 is not a serial rate"), std::string::npos);
  std::remove(file.c_str());
  std::remove(fifo.c_str());
}

TEST(GrblStage, StopSignalHaltsTheStageWithinASecond) {
  GrblEmulatorOptions options;
  options.acceleration_mm_s2 = 200;  // a hold takes 0.25 s to come to rest from 50 mm/s
  GrblEmulator emulator(options);
  const std::string log_path = TempPath("stop.log");
  std::remove(log_path.c_str());
  DeviceLog log(log_path);
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  const StopSignalScope scope;  // clears the flag
  stage.Connect(TestSettings(), &log);
  Clock::time_point stop_at;
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    stop_at = Clock::now();
    RequestStop();
  });
  const Error error = Thrown([&] { stage.MoveTo({{'X', 250}}); });
  stopper.join();
  const double returned_after = Since(stop_at);
  { const StopSignalScope clear; }  // a scope starts with the flag cleared
  EXPECT_EQ(error.exit_code(), 1);
  EXPECT_EQ(std::string(error.what()), Uri(emulator) + ": moving to X=250: stopped by a signal");
  EXPECT_LT(returned_after, 1.0);
  // The emulator saw the feed hold, then the reset, and came to rest within a second.
  Clock::time_point hold_at{}, reset_at{}, rest_at{};
  for (const auto& event : emulator.Events()) {
    if (event.text == "> !" && hold_at == Clock::time_point{}) hold_at = event.at;
    if (event.text == "> <0x18>" && event.at > stop_at) reset_at = event.at;
    if (event.text == "state Hold:0" || event.text == "state Alarm") {
      if (rest_at == Clock::time_point{}) rest_at = event.at;
    }
  }
  ASSERT_NE(hold_at, Clock::time_point{});
  ASSERT_NE(reset_at, Clock::time_point{});
  ASSERT_NE(rest_at, Clock::time_point{});
  EXPECT_GT(hold_at, stop_at);
  EXPECT_GT(reset_at, hold_at);
  EXPECT_LT(std::chrono::duration<double>(rest_at - stop_at).count(), 1.0);
  EXPECT_EQ(emulator.State(), "Idle");  // held to rest first: no ALARM:3, position kept
  const auto rest = emulator.Position();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(emulator.Position(), rest);
  EXPECT_GT(rest[0], 10);
  EXPECT_LT(rest[0], 100);
  const std::string text = FileText(log_path);
  for (const char* line :
       {"> !", "< <Hold:1|", "< <Hold:0|", "# halted: feed hold, then soft reset"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << " not in\n" << text;
  }
}

TEST(GrblStage, ResetDuringAHoldInProgressLosesPosition) {
  // A hold that cannot finish within the driver's wait: the reset is an abort (ALARM:3), as
  // GRBL does, and the stage stops at once anyway.
  GrblEmulatorOptions options;
  options.acceleration_mm_s2 = 20;  // 1 s to rest from the 20 mm/s reached at the stop
  GrblEmulator emulator(options);
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  const StopSignalScope scope;
  stage.Connect(TestSettings(), nullptr);
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1000));
    RequestStop();
  });
  const auto start = Clock::now();
  const Error error = Thrown([&] { stage.MoveTo({{'X', 250}}); });
  stopper.join();
  { const StopSignalScope clear; }
  EXPECT_LT(Since(start), 1.0 + 1.0);
  EXPECT_NE(std::string(error.what()).find("stopped by a signal"), std::string::npos);
  EXPECT_TRUE(HasEvent(emulator, "< ALARM:3"));
  EXPECT_EQ(emulator.State(), "Alarm");
}

TEST(GrblStage, MoveNotAtRestInTimeIsHalted) {
  GrblEmulator emulator;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  StageSettings settings = TestSettings();
  settings.move_timeout_s = 0.3;
  stage.Connect(settings, nullptr);
  const auto start = Clock::now();
  const Error error = Thrown([&] { stage.MoveTo({{'X', 200}}); });
  EXPECT_LT(Since(start), 0.3 + 0.1 + 1.0);
  EXPECT_EQ(std::string(error.what()),
            Uri(emulator) + ": moving to X=200: not at rest within 0.3 s (move_timeout_s); halted");
  EXPECT_TRUE(HasEvent(emulator, "> !"));
  EXPECT_TRUE(HasEvent(emulator, "> <0x18>"));
  EXPECT_NE(emulator.State(), "Run");
}

TEST(GrblStage, StopSignalDuringHomingResets) {
  GrblEmulatorOptions options;
  options.require_homing = true;
  options.homing_s = 5;
  GrblEmulator emulator(options);
  StageSettings settings = TestSettings();
  settings.home = true;
  GrblStage stage(Uri(emulator), emulator.SlavePath(), 115200);
  const StopSignalScope scope;
  stage.Connect(settings, nullptr);
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    RequestStop();
  });
  const auto start = Clock::now();
  const Error error = Thrown([&] { stage.Home(); });
  stopper.join();
  { const StopSignalScope clear; }
  EXPECT_LT(Since(start), 0.3 + 1.0);
  EXPECT_EQ(std::string(error.what()), Uri(emulator) + ": homing ($H): stopped by a signal");
  EXPECT_TRUE(HasEvent(emulator, "< ALARM:6"));  // homing reset, as GRBL reports it
  EXPECT_FALSE(HasEvent(emulator, "> !"));       // GRBL ignores a feed hold while homing
}

// The emulator answers as GRBL 1.1 does (doc/markdown/interface.md, commands.md).
TEST(GrblEmulator, AnswersLikeGrbl) {
  GrblEmulatorOptions options;
  options.speed_factor = 50;
  GrblEmulator emulator(options);
  SerialPort port("grbl:test", emulator.SlavePath(), 115200);
  const auto reply = [&](const std::string& bytes) {
    port.Write(bytes);
    std::string line;
    EXPECT_EQ(port.ReadLine(1, &line), SerialPort::Read::kLine) << bytes;
    return line;
  };
  EXPECT_EQ(reply("\x18"), "Grbl 1.1h ['$' for help]");
  EXPECT_EQ(reply("G21 G90\n"), "ok");
  EXPECT_EQ(reply("\n"), "ok");                // an empty line, for syncing
  EXPECT_EQ(reply("G2 X1\n"), "error:20");     // not emulated: unsupported command
  EXPECT_EQ(reply("G1 X1\n"), "error:22");     // no feed rate yet
  EXPECT_EQ(reply("G0 G1 X1\n"), "error:21");  // modal group violation
  EXPECT_EQ(reply("G0 X1 X2\n"), "error:25");  // repeated word
  EXPECT_EQ(reply("G0 X\n"), "error:2");       // bad number format
  EXPECT_EQ(reply("1 X\n"), "error:1");        // expected command letter
  EXPECT_EQ(reply("$Q\n"), "error:3");         // invalid statement
  EXPECT_EQ(reply("G1 X2 Y3 F6000\n"), "ok");
  EXPECT_EQ(reply("G91 G0 X1\n"), "ok");  // relative to the planned end
  for (int i = 0; i < 100 && emulator.State() != "Idle"; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(reply("?"), "<Idle|MPos:3.000,3.000,0.000|FS:0,0|WCO:0.000,0.000,0.000>");
  EXPECT_EQ(reply("$X\n"), "ok");  // not locked: nothing to say
  emulator.RequireHoming(true);
  EXPECT_EQ(reply("G0 X0\n"), "error:9");
  EXPECT_EQ(reply("$X\n"), "[MSG:Caution: Unlocked]");
  std::string line;
  ASSERT_EQ(port.ReadLine(1, &line), SerialPort::Read::kLine);
  EXPECT_EQ(line, "ok");
  EXPECT_EQ(reply("G90 G0 X999\n"), "ALARM:2");
  EXPECT_EQ(port.ReadLine(1, &line), SerialPort::Read::kLine);
  EXPECT_EQ(line, "[MSG:Reset to continue]");
  EXPECT_EQ(reply("\x18"), "ok");  // the interrupted line's answer comes after the reset
  EXPECT_EQ(port.ReadLine(1, &line), SerialPort::Read::kLine);
  EXPECT_EQ(line, "Grbl 1.1h ['$' for help]");
  EXPECT_EQ(port.ReadLine(1, &line), SerialPort::Read::kLine);
  EXPECT_EQ(line, "[MSG:'$H'|'$X' to unlock]");
  const std::string status = reply("?");
  EXPECT_EQ(status.rfind("<Alarm|MPos:3.000,3.000,0.000|", 0), 0u) << status;
}

}  // namespace
}  // namespace lumislab
