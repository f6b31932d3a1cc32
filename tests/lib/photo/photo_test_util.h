// Shared by the photo tests: a scratch folder per test and checks of BadInput.
#pragma once

#include <functional>
#include <string>

namespace lumislab::testing {

// A fresh, empty folder for the running test (removed and recreated).
std::string ScratchDir();
// Runs `body`; true when it throws lumislab's BadInput (exit 2) whose message names `path`.
// The message is stored in *message.
bool ThrowsBadInputNaming(const std::function<void()>& body, const std::string& path,
                          std::string* message);

}  // namespace lumislab::testing
