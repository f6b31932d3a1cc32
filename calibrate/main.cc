#include "calibrate/cli.h"
#include "core/error.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("calibrate", [&] { return lumislab::RunCalibrate(argc, argv); });
}
