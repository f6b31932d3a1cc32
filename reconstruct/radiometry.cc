#include "reconstruct/radiometry.h"

#include <filesystem>

#include "core/log.h"
#include "lib/photometry/colour.h"

namespace lumislab {

ReconstructRadiometry LoadReconstructRadiometry(const Dataset& dataset) {
  ReconstructRadiometry r;
  const std::string calib = dataset.Path("calib");
  const PhotoCorrections c = LoadPhotoCorrections(calib);
  if (!c.Empty()) r.corrections = std::make_shared<PhotoCorrections>(c);
  if (c.dark)
    LogInfo("dark: subtracting ", c.dark->file, " (",
            c.dark->current.empty() ? "constant level" : "offset + current x exposure", ", ",
            c.dark->hot_count, " hot pixel(s) read as their neighbours' mean)");
  if (c.response) LogInfo("response: 8-bit photos linearised through ", c.response->file);
  if (c.flat) LogInfo("flat: dividing out ", c.flat->file);
  const std::string scale_file = calib + "/scale.json";
  if (std::filesystem::exists(scale_file)) {
    const RadiometricScale s = LoadRadiometricScale(scale_file);
    r.scale = s.scale;
    r.units = s.units;
    r.scale_source = scale_file;
    r.channel_weights = s.channel_weights;
    r.channel_weights_from_colour = s.from_colour;
    LogInfo("scale: ", s.scale, " ", s.units, " per unit from ", scale_file,
            dataset.radiometric_scale
                ? " (dataset.json radiometry.scale_w_m2 " +
                      std::to_string(*dataset.radiometric_scale) + " not used)"
                : std::string(),
            "; luminance weights ", s.channel_weights.x(), " ", s.channel_weights.y(), " ",
            s.channel_weights.z(), s.from_colour ? " (colour calibration)" : " (Rec. 709)");
    // A colour calibration made after the scale: the reading was matched to other weights.
    if (const auto colour = ColourCalibration::LoadFor(dataset.dir))
      if ((colour->LuminanceWeights() - s.channel_weights).norm() > 1e-9)
        LogWarning(scale_file, ": channel_weights ", s.from_colour ? "differ from" : "are not",
                   " the luminance weights of ", colour->file,
                   " (calibrated after the scale?): the slab keeps the scale's; run "
                   "lumislab-calibrate scale --force, then reconstruct --force");
  } else if (dataset.radiometric_scale) {
    r.scale = dataset.radiometric_scale;
    r.units = "W/m^2";
    r.scale_source = dataset.Path("dataset.json");
    LogInfo("scale: ", *r.scale, " W/m^2 per unit from dataset.json radiometry.scale_w_m2");
  } else {
    LogInfo("scale: none (no calib/scale.json, no radiometry.scale_w_m2): relative units");
  }
  return r;
}

}  // namespace lumislab
