#include "core/error.h"
#include "reconstruct/reconstructor.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("reconstruct", [&] { return lumislab::RunReconstruct(argc, argv); });
}
