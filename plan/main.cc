#include "core/error.h"
#include "plan/plan.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("plan", [&] { return lumislab::RunPlan(argc, argv); });
}
