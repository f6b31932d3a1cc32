#include "core/error.h"
#include "plan/cli.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("plan", [&] { return lumislab::RunPlan(argc, argv); });
}
