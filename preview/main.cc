#include "core/error.h"
#include "preview/cli.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("preview", [&] { return lumislab::RunPreview(argc, argv); });
}
