#include "preview/reference_mode.h"

#include <chrono>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "lib/lightfield/reference_render.h"
#include "lib/lightfield/tone_map.h"
#include "lib/synthetic/scene.h"
#include "preview/config.h"
#include "preview/image_files.h"

namespace lumislab {
namespace {

// The synthetic luminaire's emitters as the reference's point sources: in the frame of its
// positions (a slab's: S at z = 0), or for a luminaire folder in the luminaire's own frame (the
// origin at its centre_mm, the frame the folder's poses map from).
std::vector<PointSource> PointSources(const Luminaire& luminaire, bool own_frame) {
  const Eigen::Vector3d origin = own_frame ? luminaire.centre_mm : Eigen::Vector3d::Zero();
  std::vector<PointSource> sources;
  for (const Emitter& e : luminaire.emitters)
    sources.push_back(
        {e.position_mm - origin, [e](const Eigen::Vector3d& w) { return e.Intensity(w); }});
  return sources;
}

}  // namespace

int RunReferenceMode(const PreviewConfig& config, const SlabInfo& info) {
  const SceneSetup setup = MakePreviewSetup(config, info);
  ReferenceOptions options;
  options.samples = config.samples;
  options.threads = config.threads;
  options.visibility = config.shadows;
  options.whole_frame = config.luminaire_folder;  // the luminaire's own frame, every direction
  // Inputs first: a bad luminaire or slab is refused before the scene is built.
  const bool analytic = !config.analytic.empty();
  const Luminaire luminaire = analytic ? LoadLuminaire(config.analytic) : Luminaire{};
  RequirePointEmitters(luminaire, config.analytic, "--analytic");
  const std::vector<ImageF> irradiance =
      analytic ? std::vector<ImageF>{} : ReadSlabIrradiance(config.slab_dir, info, config.threads);
  const ReferenceScene view(setup, config.width, config.height);
  const auto start = std::chrono::steady_clock::now();
  const ReferenceImage image =
      analytic ? RenderPointSources(view, PointSources(luminaire, options.whole_frame), options)
               : RenderReference(view, info, irradiance, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!image.complete) throw Failure("stopped by a signal; " + config.out + " not written");
  if (config.false_colour)  // the irradiance, before albedo: as the OpenGL false-colour view
    WriteImageOrPicture(config.out, image.irradiance,
                        FalseColourView(config, setup, info, image.irradiance));
  else
    WriteImage(config.out, image.image, config.tone);
  if (analytic)
    LogInfo("analytic image of ", config.analytic, " (", luminaire.emitters.size(), " emitters), ",
            setup.mesh.triangles(), " triangles, ", view.width(), "x", view.height(), " in ",
            seconds, " s -> ", config.out);
  else
    LogInfo("exact reference, N = ", options.samples, " (", options.samples * options.samples,
            " samples per support), ", info.present.size(), "/", info.grid.count(), " positions, ",
            setup.mesh.triangles(), " triangles, ", view.width(), "x", view.height(), " in ",
            seconds, " s -> ", config.out);
  return 0;
}

}  // namespace lumislab
