#include "core/error.h"
#include "export/cli.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("export", [&] { return lumislab::RunExport(argc, argv); });
}
