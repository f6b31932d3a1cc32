// Photos (lib/photo/photo_io.h DecodePhoto): the bytes are <tmp>/in/photo (no extension: the
// format is detected from the content, so PNG, JPEG, TIFF and OpenEXR all reach it), then turned
// into linear values the way calibrate (LinearGray) and reconstruct (LinearReader) read them.
#include "fuzz/fuzz_util.h"
#include "lib/photo/photo_io.h"

using namespace lumislab;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = fuzz::SubDir("in") + "/photo";
  fuzz::WriteFile(path, data, size);
  FUZZ_BEGIN
  const Photo photo = DecodePhoto(path);
  const cv::Mat gray = LinearGray(photo);
  if (gray.rows != photo.pixels.rows || gray.cols != photo.pixels.cols)
    fuzz::Finding("LinearGray: size differs from the photo");
  // An 8-bit or 16-bit photo read as sRGB, with a black and white level and an exposure.
  PhotoSpec spec;
  spec.transfer = Transfer::kSrgb;
  spec.black_level = 0.01;
  spec.white_level = 0.9;
  spec.saturation_level = 0.95;
  spec.exposure = 0.25;
  Photo srgb = photo;
  srgb.spec = spec;
  if (photo.CodeBits() < 32) srgb.transfer = Transfer::kSrgb;
  const LinearReader reader(srgb);
  float rgb[3];
  bool clipped[3];
  reader.Read(0, 0, rgb, clipped);
  reader.Read(photo.pixels.rows - 1, photo.pixels.cols - 1, rgb, clipped);
  (void)srgb.SaturationCode();
  (void)srgb.Gain();
  (void)srgb.Offset();
  FUZZ_END
}
