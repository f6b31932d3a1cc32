#include "core/error.h"
#include "reconstruct/cli.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("reconstruct", [&] { return lumislab::RunReconstruct(argc, argv); });
}
