#include "core/error.h"
#include "study/cli.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("study", [&] { return lumislab::RunStudy(argc, argv); });
}
