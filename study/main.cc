#include "core/error.h"
#include "study/study.h"

int main(int argc, char** argv) {
  return lumislab::RunMain("study", [&] { return lumislab::RunStudy(argc, argv); });
}
