#include "acquire/cli.h"
#include "core/error.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("acquire", [&] { return lumislab::RunAcquire(argc, argv); });
}
