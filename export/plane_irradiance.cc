#include "export/plane_irradiance.h"

#include "core/stop_signal.h"
#include "lib/lightfield/reference_render.h"
#include "lib/lightfield/scene_setup.h"

namespace lumislab {

PlaneIrradiance RenderPlaneIrradiance(const SlabInfo& info, const std::vector<ImageF>& irradiance,
                                      double distance_mm, double extent_mm, int size, int samples,
                                      int threads) {
  SceneRequest scene;
  scene.name = "plane";
  scene.receiver_plane_mm = distance_mm;
  scene.extent_mm = extent_mm;
  const SceneSetup setup = MakeSceneSetup(scene, info);
  const ReferenceScene view(setup, size, size);
  ReferenceOptions options;
  options.samples = samples;
  options.threads = threads;
  options.visibility = false;  // the plane alone: nothing casts a shadow
  const StopSignalScope stop_signals;
  ReferenceImage image = RenderReference(view, info, irradiance, options);
  PlaneIrradiance out;
  out.irradiance = std::move(image.irradiance);
  out.plane_z_mm = setup.plane_z;
  out.extent_mm = setup.extent;
  out.complete = image.complete;
  return out;
}

}  // namespace lumislab
