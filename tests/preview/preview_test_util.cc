#include "preview_test_util.h"

#include "core/error.h"
#include "preview/cli.h"

namespace lumislab {

int RunPreviewWith(std::vector<std::string> args) {
  args.insert(args.begin(), "lumislab-preview");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  return RunMain("preview", [&] { return RunPreview(int(argv.size()), argv.data()); });
}

}  // namespace lumislab
