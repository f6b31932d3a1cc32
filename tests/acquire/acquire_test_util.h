// Small scenes and folders for the acquire tests.
#pragma once

#include <string>

#include "lib/synthetic/scene.h"

namespace lumislab::acquire_test {

// A 3x3 grid, 320x240 camera behind the screen, the default two-emitter luminaire.
std::string SmallSceneJson(const std::string& effects_json = "[]",
                           const std::string& camera_extra = "");
SynthScene SmallScene(const std::string& effects_json = "[]");
// A fresh empty folder under the temp folder.
std::string FreshDir(const std::string& name);

}  // namespace lumislab::acquire_test
