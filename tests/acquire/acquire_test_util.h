// Small scenes and folders for the acquire tests.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "acquire/synth.h"
#include "lib/synthetic/scene.h"

namespace lumislab::acquire_test {

// A 3x3 grid, 320x240 camera behind the screen, the default two-emitter luminaire.
std::string SmallSceneJson(const std::string& effects_json = "[]",
                           const std::string& camera_extra = "");
SynthScene SmallScene(const std::string& effects_json = "[]");
// A fresh empty folder under the temp folder.
std::string FreshDir(const std::string& name);
// A file's bytes.
std::string FileBytes(const std::string& path);
// Synth options for the small scenes: float photos, 20-texel truth, 2 threads, into `out`.
SynthOptions SmallSynthOptions(const std::string& out);
// Each (effects JSON, field) case: SmallScene refuses it as bad input, the message starting with
// "small.json: <field>: expected ".
void ExpectEffectsRefused(const std::vector<std::pair<std::string, std::string>>& cases);

}  // namespace lumislab::acquire_test
