#include "calibrate/cli_colour.h"

#include <filesystem>

#include "core/atomic_file.h"
#include "core/checks.h"
#include "core/dataset.h"
#include "core/error.h"
#include "core/log.h"
#include "lib/photo/radiometric_calibration.h"

namespace lumislab {

void AddColourCommand(CLI::App* app, CommonOptions* common, ColourCommand* c) {
  c->sub = app->add_subcommand(
      "colour",
      "a photo of a ColorChecker Classic 24 -> calib/colour.json: the 3x3 matrix from the "
      "camera's linear RGB to CIE 1931 XYZ (least squares against the chart's reference "
      "colours under the stated illuminant), for the chromaticity and CCT of the light");
  c->sub->add_option("--photo", c->photo, "the chart photo (any format the decoder reads)")
      ->required();
  c->sub
      ->add_option("--out", c->out,
                   "a dataset folder (writes calib/colour.json; the photo is linearised with "
                   "its response and dark calibration) or a .json file")
      ->required();
  c->sub
      ->add_option("--illuminant", c->options.illuminant,
                   "the light on the chart: D50 or D65 (daylight, a D65 simulator)")
      ->capture_default_str();
  c->sub->add_flag("--force", c->force, "replace an existing output file");
  AddCommonOptions(c->sub, common);
}

int RunColourCommand(ColourCommand* c) {
  c->options.Check();
  c->out = TrimTrailingSlashes(c->out);
  LogInfo("parameters: colour photo=", c->photo, " out=", c->out,
          " illuminant=", c->options.illuminant, " force=", c->force ? "yes" : "no");
  const bool to_dataset = std::filesystem::exists(std::filesystem::path(c->out) / "dataset.json");
  if (!to_dataset && std::filesystem::path(c->out).extension() != ".json")
    throw BadInput("--out: expected a dataset folder (with dataset.json) or a .json file, got '" +
                   c->out + "'");
  std::string out = c->out, dataset_dir;
  PhotoSpec spec;
  if (to_dataset) {
    const Dataset dataset = Dataset::Load(c->out);
    dataset_dir = dataset.dir;
    out = dataset.Path("calib/colour.json");
    spec = PhotoSpecOf(dataset, PhotoEntry{});  // exposure 1, the dataset's clipping level
    // The response and dark level apply to any photo of the camera; the flat field is the
    // screen's and does not.
    spec.corrections = std::make_shared<PhotoCorrections>(
        LoadPhotoCorrections(dataset.Path("calib"), {true, true, false}));
  }
  RefuseOutputOverInputs(out, to_dataset ? out : "");
  if (std::filesystem::exists(out) && !c->force)
    throw BadInput(out + ": exists; use --force to replace it");
  const Photo photo = DecodePhoto(c->photo, spec);
  CheckLog checks(dataset_dir, "calibrate colour");
  const ChartPatches patches = FindColourChart(photo, ChartReferenceXyz(c->options.illuminant),
                                               ReferenceWhite(c->options.illuminant));
  nlohmann::json report;
  const ColourCalibration calibration =
      CalibrateColour(patches, c->options, c->photo, &report, &checks);
  if (to_dataset) {
    MakeDirectories(std::filesystem::path(out).parent_path().string());
    RemoveOrphanedTemporaries(std::filesystem::path(out).parent_path().string());
  }
  SaveColourCalibration(out, calibration, report);
  checks.Save();
  const Eigen::Vector3d w = calibration.LuminanceWeights();
  LogInfo("colour: ColorChecker under ", c->options.illuminant, ", Delta E*ab mean ",
          Num(calibration.mean_delta_e), " max ", Num(calibration.max_delta_e),
          "; luminance weights R G B ", Num(w.x()), " ", Num(w.y()), " ", Num(w.z()), " -> ", out);
  return 0;
}

}  // namespace lumislab
