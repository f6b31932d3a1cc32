// Ground truth of a synthetic capture (truth/): the exact E_ij of a luminaire at the slab texel
// centres, and the true camera (truth/camera.json) for the calibration tests. The capture, the
// preview's tests and benchmarks and `lumislab-preview --write-test-slab` all take their exact
// slabs from here.
#pragma once

#include <string>

#include "core/slab.h"
#include "lib/synthetic/luminaire.h"
#include "lib/synthetic/scene.h"

namespace lumislab {

// Exact E_ij(s,t) (W/m^2, luminaire frame) at the texel centres of `info` through its filter,
// mask 1 everywhere.
SlabPosition TruthPosition(const Luminaire& luminaire, const SlabInfo& info, int i, int j);

// A complete truth slab in `dir`: every position of info.grid and slab.json, positions computed
// and written on `threads` threads. A slab in units "lux" holds what a lux meter reads,
// `luminous_efficacy` (lm/W, SynthScene::LuminousEfficacy) x the W/m^2 of TruthPosition.
void WriteTruthSlab(const Luminaire& luminaire, SlabInfo info, const std::string& dir, int threads,
                    double luminous_efficacy = DefaultLuminousEfficacy());

// The slab layout of a scene's capture at `resolution` texels per side (d, grid, screen window,
// filter, W/m^2).
SlabInfo TruthSlabInfo(const SynthScene& scene, int resolution);

// The built-in scene's setup (d = 750 mm, 1.2 m window, K = 1) with an nu x nv grid of spacing
// h: the slab layout the preview's tests and benchmarks light scenes with.
SlabInfo DefaultSlabInfo(int nu, int nv, double spacing_mm, int resolution);

// True when the slab holds all the light of every emitter towards point x (luminaire frame, mm):
// the ray crosses S where the grid's dual filters sum to 1, |u| <= ((nu - 1)/2 - K) h and
// |v| <= ((nv - 1)/2 - K) h for a truncated dual with K + 1 coefficients, and meets M inside the
// slab window, less the spread |1 - d / x_z| (K + 2) h of the rays a reconstruction draws from
// the supports around it (docs/method.md §4.5). Elsewhere images from the slab fall short of the
// analytic truth however exact the renderer. Point emitters only: ray sources are not looked at
// (their users, the analytic images and the study, refuse them: RequirePointEmitters).
bool GridCovers(const Luminaire& luminaire, const SlabInfo& info, const Eigen::Vector3d& x);
// truth/camera.json: intrinsics, pose (lab frame), and the exact homographies of the screen
// plane (screen_from_image: pixel -> lab mm, row-major, and its inverse).
void WriteTruthCamera(const SynthScene& scene, const std::string& path);

// truth/luminaire.json (schema 1): {"schema_version": 1, "luminaire": {"emitters": [...]}}, the
// scene file's luminaire block, so that the analytic image (lumislab-preview --analytic) can be
// asked for from the dataset folder (LoadLuminaire reads it back).
void WriteTruthLuminaire(const Luminaire& luminaire, const std::string& path);
// truth/response.json (scenes with a `response` effect): the camera curve's parameters and, for
// each 8-bit code k, the linear value it stands for (the curve's inverse at k / 255), so that a
// test can hand a decoder the true curve.
void WriteTruthResponse(const ResponseEffect& response, const std::string& path);

}  // namespace lumislab
