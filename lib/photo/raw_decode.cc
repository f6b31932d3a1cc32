#include "lib/photo/raw_decode.h"

#include <libraw.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <ctime>
#include <memory>

#include "core/error.h"
#include "lib/photo/photo_allocator.h"
#include "lib/photo/photo_format.h"

namespace lumislab {
namespace {

// LibRaw reports a short read or corrupt data through this callback (and by default prints to
// stderr); the decoder turns it into BadInput after unpacking.
void RecordDataError(void* data, const char* /*file*/, const int /*offset*/) {
  *static_cast<bool*>(data) = true;
}

// LibRaw is large (its colour data alone is ~0.5 MB), so it lives on the heap. The thread-safe
// build (libraw_r) keeps all state in the object, so decoders may run in parallel.
struct OpenRaw {
  std::unique_ptr<LibRaw> raw = std::make_unique<LibRaw>();
  bool data_error = false;
  int open_code = LIBRAW_UNSPECIFIED_ERROR;
  explicit OpenRaw(const std::string& path) {
    raw->set_dataerror_handler(&RecordDataError, &data_error);
    open_code = raw->open_file(path.c_str());
  }
};

// The 2x2 Bayer pattern as channel indices 0 (R), 1 (G), 2 (B); false when the sensor is not a
// 2x2 Bayer mosaic (LibRaw's `filters` encodes 8 rows x 2 columns).
bool BayerPattern(LibRaw& raw, int pattern[2][2]) {
  const libraw_iparams_t& id = raw.imgdata.idata;
  if (id.filters < 1000 || id.colors != 3 || id.is_foveon) return false;
  int count[3] = {0, 0, 0};
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 2; ++c) {
      const int color = raw.FC(r, c);
      if (color != raw.FC(r % 2, c)) return false;  // not a 2-row period
      if (r < 2) {
        const int channel = color == 3 ? 1 : color;  // 3: the second green
        pattern[r][c] = channel;
        ++count[channel];
      }
    }
  return count[0] == 1 && count[1] == 2 && count[2] == 1;
}

}  // namespace

bool LibRawIdentifiesRaw(const std::string& path) {
  try {
    OpenRaw open(path);
    int pattern[2][2];
    return open.open_code == LIBRAW_SUCCESS && BayerPattern(*open.raw, pattern);
  } catch (const std::bad_alloc&) {
    return false;
  }
}

RawImage DecodeRaw(const std::string& path, bool half_size) {
  OpenRaw open(path);
  LibRaw& raw = *open.raw;
  if (open.open_code != LIBRAW_SUCCESS)
    throw BadInput(path + ": cannot decode the camera RAW: " + LibRaw::strerror(open.open_code));
  const libraw_image_sizes_t& sizes = raw.imgdata.sizes;
  const long long raw_pixels = (long long)sizes.raw_width * sizes.raw_height;
  if (sizes.width < 2 || sizes.height < 2 || raw_pixels > kMaxPhotoPixels)
    throw InputError(path, "image size",
                     "a RAW of 2x2 .. " + std::to_string(kMaxPhotoPixels) + " pixels",
                     std::to_string(sizes.raw_width) + "x" + std::to_string(sizes.raw_height));
  int pattern[2][2];
  if (!BayerPattern(raw, pattern))
    throw InputError(path, "sensor layout", "a 2x2 Bayer mosaic",
                     "filters " + std::to_string(raw.imgdata.idata.filters) + ", " +
                         std::to_string(raw.imgdata.idata.colors) + " colours");
  const int code = raw.unpack();
  if (code != LIBRAW_SUCCESS)
    throw BadInput(path + ": cannot decode the camera RAW: " + LibRaw::strerror(code));
  if (open.data_error) throw BadInput(path + ": truncated or corrupt camera RAW data");
  const ushort* codes = raw.imgdata.rawdata.raw_image;
  if (!codes) throw InputError(path, "raw data", "a Bayer mosaic of integers", "another layout");

  // Black level of a visible pixel: common + per channel + repeat pattern, as LibRaw keeps them
  // before its own processing (rawdata.color is the state right after unpacking).
  const libraw_colordata_t& color = raw.imgdata.rawdata.color;
  const libraw_image_sizes_t& rs = raw.imgdata.rawdata.sizes;
  const unsigned pattern_rows = color.cblack[4], pattern_cols = color.cblack[5];
  const bool black_pattern =
      pattern_rows > 0 && pattern_cols > 0 && 6 + pattern_rows * pattern_cols <= LIBRAW_CBLACK_SIZE;
  auto black = [&](int y, int x) {
    double b = color.black + color.cblack[raw.COLOR(y, x)];
    if (black_pattern) b += color.cblack[6 + (y % pattern_rows) * pattern_cols + x % pattern_cols];
    return b;
  };
  const double white = color.maximum;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x)
      if (!(white > black(y, x)))
        throw InputError(path, "white level",
                         "above the black level (" + std::to_string(black(y, x)) + ")",
                         std::to_string(white));

  // The visible mosaic, normalised per sample; not clipped at 0, so noise averages out.
  const int w = rs.width, h = rs.height;
  const size_t pitch = rs.raw_pitch / sizeof(ushort);
  // NewPhotoImage: huge pages, reused from the previous photo of the size (a 6000 x 4000 DNG's
  // mosaic and RGB image are 96 + 288 MB, ~94000 fresh 4 kB pages to fault in otherwise).
  cv::Mat mosaic = NewPhotoImage(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y) {
    const ushort* row = codes + size_t(y + rs.top_margin) * pitch + rs.left_margin;
    float* out = mosaic.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const double b = black(y, x);
      out[x] = float((row[x] - b) / (white - b));
    }
  }

  RawImage image;
  const float* mul = color.cam_mul;
  if (mul[1] > 0 && std::isfinite(mul[0]) && std::isfinite(mul[2]) && mul[0] > 0 && mul[2] > 0)
    image.as_shot_white_balance = {mul[0] / mul[1], 1.f, mul[2] / mul[1]};

  if (half_size) {
    image.rgb = NewPhotoImage(h / 2, w / 2, CV_32FC3);
    for (int y = 0; y < h / 2; ++y)
      for (int x = 0; x < w / 2; ++x) {
        float sum[3] = {0, 0, 0};
        bool clipped[3] = {false, false, false};
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const float v = mosaic.at<float>(2 * y + dy, 2 * x + dx);
            sum[pattern[dy][dx]] += v;
            clipped[pattern[dy][dx]] |= v >= 1.f;
          }
        cv::Vec3f rgb(sum[0], sum[1] / 2, sum[2]);
        for (int c = 0; c < 3; ++c)
          if (clipped[c]) rgb[c] = std::max(rgb[c], 1.f);  // a clipped sample clips the mean
        image.rgb.at<cv::Vec3f>(y, x) = rgb;
      }
    return image;
  }
  image.rgb = NewPhotoImage(h, w, CV_32FC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float sum[3] = {0, 0, 0};
      int count[3] = {0, 0, 0};
      bool clipped[3] = {false, false, false};
      for (int yy = std::max(y - 1, 0); yy <= std::min(y + 1, h - 1); ++yy)
        for (int xx = std::max(x - 1, 0); xx <= std::min(x + 1, w - 1); ++xx) {
          const int c = pattern[yy & 1][xx & 1];
          const float v = mosaic.at<float>(yy, xx);
          sum[c] += v;
          clipped[c] |= v >= 1.f;
          ++count[c];
        }
      cv::Vec3f& out = image.rgb.at<cv::Vec3f>(y, x);
      const int own = pattern[y & 1][x & 1];
      for (int c = 0; c < 3; ++c) {
        out[c] = c == own ? mosaic.at<float>(y, x) : sum[c] / count[c];
        // An interpolated value that used a clipped sample is unknown, not a darker one: it
        // counts as clipped too (at the white level, 1), so the merge leaves it out.
        if (c != own && clipped[c]) out[c] = std::max(out[c], 1.f);
      }
    }
  return image;
}

PhotoExif ReadRawExif(const std::string& path) {
  OpenRaw open(path);
  if (open.open_code != LIBRAW_SUCCESS)
    throw BadInput(path +
                   ": cannot read the camera RAW's EXIF: " + LibRaw::strerror(open.open_code));
  const libraw_data_t& d = open.raw->imgdata;
  auto positive = [](float v) {
    return v > 0 && std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
  };
  auto text = [](const char* s, size_t size) {
    const std::string t(s, strnlen(s, size));
    return t.empty() ? std::nullopt : std::optional<std::string>(t);
  };
  PhotoExif exif;
  exif.exposure_time = positive(d.other.shutter);
  exif.f_number = positive(d.other.aperture);
  exif.iso = positive(d.other.iso_speed);
  exif.make = text(d.idata.make, sizeof d.idata.make);
  exif.model = text(d.idata.model, sizeof d.idata.model);
  exif.lens_model = text(d.lens.Lens, sizeof d.lens.Lens);
  exif.focal_length = positive(d.other.focal_len);
  // LibRaw's flip (0 none, 3 180 degrees, 5 and 6 90 degrees, 1 2 4 7 mirrored) back to the
  // EXIF Orientation it was read from.
  constexpr int kOrientationOfFlip[8] = {1, 2, 4, 3, 5, 8, 6, 7};
  if (d.sizes.flip >= 0 && d.sizes.flip < 8) exif.orientation = kOrientationOfFlip[d.sizes.flip];
  if (d.other.timestamp > 0) {
    // LibRaw turned the EXIF text into a time_t with mktime (local time); localtime undoes it.
    std::tm t{};
    const time_t stamp = d.other.timestamp;
    char buffer[32];
    if (localtime_r(&stamp, &t) && std::strftime(buffer, sizeof buffer, "%Y:%m:%d %H:%M:%S", &t))
      exif.date_time = buffer;
  }
  return exif;
}

}  // namespace lumislab
