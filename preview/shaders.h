// The renderer's GLSL sources: preview/shaders/*, embedded in the binary at build time by
// preview/embed_shaders.cmake (each file's opening comment says what it does; `#include "x.glsl"`
// lines hold x.glsl's text). Programs that take #defines get them after the first line
// (gl_program.h, WithDefines).
#pragma once

namespace lumislab::shaders {

extern const char* const kSceneVertex;            // scene.vert
extern const char* const kGeometryFragment;       // geometry.frag: the G-buffer
extern const char* const kShadowVertex;           // shadow.vert: SHADOW_BATCH still to replace
extern const char* const kEmptyFragment;          // empty.frag: the shadow maps' fragments
extern const char* const kQuadVertex;             // quad.vert: the full-screen passes
extern const char* const kLightPass;              // light_pass.glsl: fragment or compute shader
extern const char* const kTileBoundsCompute;      // tile_bounds.comp
extern const char* const kTileListsCompute;       // tile_lists.comp
extern const char* const kDisplayFragment;        // display.frag
extern const char* const kConeTaperCheckCompute;  // cone_taper_check.comp: the blend taper alone
extern const char* const kExactArgsCompute;       // exact_args.comp: EXACT_LIST's dispatch size

}  // namespace lumislab::shaders
