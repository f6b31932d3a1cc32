// Scene meshes of lumislab-preview --scene <file> (lib/lightfield/scenes.h LoadSceneFile): the
// bytes are <tmp>/in/scene.<FUZZ_MESH_EXTENSION> (built once per extension: Assimp picks its
// importer from the extension first). What is fuzzed in this process is lumislab's side: the PLY
// pre-check and the reading and checking of what the import child sends back. Assimp itself runs
// in the forked child (its coverage is not seen here); an abort or a loop in it must come back as
// a BadInput naming the file, within the 5 s given to it here.
#include <cmath>

#include "fuzz/fuzz_util.h"
#include "lib/lightfield/scenes.h"

#ifndef FUZZ_MESH_EXTENSION
#error "define FUZZ_MESH_EXTENSION (\"ply\", \"obj\")"
#endif

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = fuzz::SubDir("in") + "/scene." FUZZ_MESH_EXTENSION;
  fuzz::WriteFile(path, data, size);
  FUZZ_BEGIN
  const Mesh m = LoadSceneFile(path, 5.0);
  if (m.positions.size() % 3 != 0 || m.normals.size() != m.positions.size() ||
      m.albedo.size() != m.positions.size())
    fuzz::Finding("LoadSceneFile: positions, normals and albedo differ in size");
  for (const auto& p : m.positions)
    if (!p.allFinite()) fuzz::Finding("LoadSceneFile: a non-finite vertex was accepted");
  FUZZ_END
}
