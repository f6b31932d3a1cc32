#include "lib/photo/jpeg_decode.h"

#include <jpeglib.h>

#include <csetjmp>
#include <cstdio>
#include <cstdlib>
// jerror.h after jpeglib.h, which it needs
#include <jerror.h>
#include <libexif/exif-data.h>

#include <memory>
#include <vector>

#include "core/error.h"
#include "lib/photo/image_codecs.h"
#include "lib/photo/photo_allocator.h"
#include "lib/photo/photo_format.h"
#include "lib/photo/photo_io.h"

namespace lumislab {
namespace {

// libjpeg reports a fatal error through error_exit, which must not return: it jumps back to
// DecodeJpeg with the message, which becomes BadInput there (no C++ object with a
// destructor lives between the setjmp and the libjpeg calls that may jump).
struct ErrorManager {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

void ErrorExit(j_common_ptr info) {
  auto* error = reinterpret_cast<ErrorManager*>(info->err);
  info->err->format_message(info, error->message);
  std::longjmp(error->jump, 1);
}

// The warnings that say the data ended early (libjpeg then pads the image with grey) are errors
// for a measurement: a truncated photo is not a photo. Other warnings (extraneous bytes before a
// marker, which some cameras write) are not.
void EmitMessage(j_common_ptr info, int level) {
  if (level < 0 && (info->err->msg_code == JWRN_JPEG_EOF || info->err->msg_code == JWRN_HIT_MARKER))
    ErrorExit(info);
}

// EXIF Orientation (1-8) from the APP1 markers libjpeg kept; 1 when there is none.
int Orientation(j_decompress_ptr info) {
  for (jpeg_saved_marker_ptr m = info->marker_list; m; m = m->next) {
    if (m->marker != JPEG_APP0 + 1 || m->data_length < 6) continue;
    ExifData* exif = exif_data_new_from_data(m->data, m->data_length);
    if (!exif) continue;
    int orientation = 1;
    if (ExifEntry* e = exif_data_get_entry(exif, EXIF_TAG_ORIENTATION))
      if (e->format == EXIF_FORMAT_SHORT && e->components == 1)
        orientation = exif_get_short(e->data, exif_data_get_byte_order(exif));
    exif_data_unref(exif);
    return orientation >= 1 && orientation <= 8 ? orientation : 1;
  }
  return 1;
}

}  // namespace

DecodedJpeg DecodeJpeg(const std::string& path) {
  CodecFile file(std::fopen(path.c_str(), "rb"));
  if (!file) throw BadInput(path + ": cannot open the photo");
  jpeg_decompress_struct info;
  ErrorManager error;
  info.err = jpeg_std_error(&error.base);
  error.base.error_exit = ErrorExit;
  error.base.emit_message = EmitMessage;
  DecodedJpeg out;  // created before the setjmp: a jump back leaves them to their destructors
  std::vector<JSAMPLE> row;
  if (setjmp(error.jump)) {
    jpeg_destroy_decompress(&info);
    throw BadInput(path + ": cannot decode the JPEG (" + error.message + ")");
  }
  jpeg_create_decompress(&info);
  jpeg_stdio_src(&info, file.get());
  jpeg_save_markers(&info, JPEG_APP0 + 1, 0xffff);
  jpeg_read_header(&info, TRUE);
  const J_COLOR_SPACE space = info.jpeg_color_space;
  const bool ycbcr = info.num_components == 3 && space == JCS_YCbCr;
  const bool grey = info.num_components == 1 && space == JCS_GRAYSCALE;
  const bool rgb = info.num_components == 3 && space == JCS_RGB;
  if (!ycbcr && !grey && !rgb) {
    const std::string got = space == JCS_CMYK ? "CMYK" : space == JCS_YCCK ? "YCCK" : "other";
    jpeg_destroy_decompress(&info);
    throw InputError(path, "colour space", "YCbCr, RGB or grey", got);
  }
  if (uint64_t(info.image_width) * info.image_height > uint64_t(kMaxPhotoPixels)) {
    const std::string size =
        std::to_string(info.image_width) + "x" + std::to_string(info.image_height);
    jpeg_destroy_decompress(&info);
    throw InputError(path, "image size",
                     "an image of 1 .. " + std::to_string(kMaxPhotoPixels) + " pixels", size);
  }
  const int orientation = Orientation(&info);
  // Y, Cb, Cr: libjpeg's inverse DCT and upsampling, no conversion (that is done below). Grey
  // and RGB: the codes as stored, RGB in OpenCV's order.
  info.out_color_space = ycbcr ? JCS_YCbCr : grey ? JCS_GRAYSCALE : JCS_EXT_BGR;
  jpeg_start_decompress(&info);
  const int w = int(info.output_width), h = int(info.output_height);
  out.fractional = ycbcr;
  out.pixels = NewPhotoImage(h, w, ycbcr ? CV_16UC3 : grey ? CV_8UC1 : CV_8UC3);
  if (ycbcr) row.resize(size_t(w) * 3);
  // Code x 256, rounded: the fixed point of Photo::fractional_codes.
  const float one = float(kFractionalCodeOne), top = 255.f * one;
  auto fixed = [&](float code) {
    return uint16_t(std::min(top, std::max(0.f, code * one)) + 0.5f);
  };
  while (info.output_scanline < info.output_height) {
    const int y = int(info.output_scanline);
    JSAMPLE* rows[1] = {ycbcr ? row.data() : out.pixels.ptr<JSAMPLE>(y)};
    jpeg_read_scanlines(&info, rows, 1);
    if (!ycbcr) continue;
    uint16_t* rgb_row = out.pixels.ptr<uint16_t>(y);
    // JFIF's conversion (ITU-R BT.601 full range), which libjpeg's integer tables round.
    for (int x = 0; x < w; ++x) {
      const float luma = row[3 * x], cb = row[3 * x + 1] - 128.f, cr = row[3 * x + 2] - 128.f;
      rgb_row[3 * x] = fixed(luma + 1.402f * cr);
      rgb_row[3 * x + 1] = fixed(luma - 0.34413629f * cb - 0.71413629f * cr);
      rgb_row[3 * x + 2] = fixed(luma + 1.772f * cb);
    }
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  ApplyOrientation(orientation, out.pixels);
  return out;
}

std::vector<unsigned char> EncodeJpeg(const cv::Mat& image, int quality) {
  LUMISLAB_CHECK((image.type() == CV_8UC3 || image.type() == CV_8UC1) && !image.empty(),
                 "EncodeJpeg: an 8-bit image of 1 or 3 channels");
  LUMISLAB_CHECK(quality >= 1 && quality <= 100, "EncodeJpeg: quality in [1, 100]");
  jpeg_compress_struct info;
  ErrorManager error;
  info.err = jpeg_std_error(&error.base);
  error.base.error_exit = ErrorExit;
  // libjpeg writes into `initial` (big enough for most images at once); when it needs more it
  // allocates a buffer of its own, which it never frees, and which `buffer` names only after
  // jpeg_finish_compress. So an error (out of memory) leaves that one, never a buffer freed
  // twice.
  std::vector<unsigned char> initial(size_t(image.total() * image.elemSize()) / 2 + 65536);
  unsigned char* buffer = initial.data();
  unsigned long size = initial.size();
  if (setjmp(error.jump)) {
    jpeg_destroy_compress(&info);
    throw Failure(std::string("libjpeg: cannot encode the JPEG: ") + error.message);
  }
  jpeg_create_compress(&info);
  jpeg_mem_dest(&info, &buffer, &size);
  info.image_width = JDIMENSION(image.cols);
  info.image_height = JDIMENSION(image.rows);
  info.input_components = image.channels();
  info.in_color_space = image.channels() == 3 ? JCS_EXT_BGR : JCS_GRAYSCALE;
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, quality, TRUE);
  jpeg_start_compress(&info, TRUE);
  while (info.next_scanline < info.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(image.ptr(int(info.next_scanline)));
    jpeg_write_scanlines(&info, &row, 1);
  }
  jpeg_finish_compress(&info);
  std::vector<unsigned char> out(buffer, buffer + size);
  jpeg_destroy_compress(&info);
  if (buffer != initial.data()) std::free(buffer);
  return out;
}

}  // namespace lumislab
