// The PTP/IP camera emulator as a program, for trying the gphoto2 command line against it:
//   build/tests/ptpip_emulator --port 15740 --seconds 600 &
//   gphoto2 --camera "PTP/IP Camera" --port ptpip:127.0.0.1:15740 --capture-image-and-download
// It prints the port it listens on, then each PTP operation it receives.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <thread>

#include "core/error.h"
#include "core/stop_signal.h"
#include "ptpip_camera_emulator.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("ptpip-emulator", [&] {
    CLI::App app(
        "A PTP/IP camera on 127.0.0.1 for libgphoto2 (tests/acquire/ptpip_camera_emulator.h)");
    int port = 15740;
    double seconds = 600;
    app.add_option("--port", port, "TCP port; 0 for any free one")->check(CLI::Range(0, 65535));
    app.add_option("--seconds", seconds, "how long to run (Ctrl-C ends it sooner)")
        ->check(CLI::PositiveNumber);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    lumislab::StopSignalScope stop_scope;
    lumislab::PtpipCameraEmulator camera(port);
    std::printf("listening on %s\n", camera.ptpip_path().c_str());
    std::fflush(stdout);
    size_t printed = 0;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end && lumislab::PauseUnlessStopped(0.1)) {
      const std::vector<std::string> operations = camera.operations();
      for (; printed < operations.size(); ++printed)
        std::printf("%s\n", operations[printed].c_str());
      std::fflush(stdout);
    }
    return 0;
  });
}
