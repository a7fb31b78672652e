// JPEG through libjpeg(-turbo), asking it for what OpenCV 4's JPEG decoder asks for the same
// read mode: grey output as libjpeg's own YCbCr-to-grey (the luma plane), colour in BGR.
// Cases OpenCV treats specially (CMYK, Exif orientation, Motion-JPEG frames that rely on the
// default Huffman tables) are left to the media module, which is OpenCV.
//
// libjpeg reports errors through error_exit, which jumps back here by longjmp. The functions
// that call setjmp hold only trivially destructible locals and allocate nothing.
//
// <cstdio> must come before jpeglib.h, which uses FILE without including it.

#include <csetjmp>
#include <cstdio>
#include <cstring>

// clang-format off
#include <jpeglib.h>
// clang-format on

#include "tools/dataset/image_codecs.hpp"

namespace parallax::codecs {
namespace {

struct JpegErrors {
  jpeg_error_mgr base{};
  std::jmp_buf jump{};
  char message[JMSG_LENGTH_MAX] = "unknown libjpeg error";
};

void OnJpegError(j_common_ptr info) {
  auto* errors = reinterpret_cast<JpegErrors*>(info->err);
  (*info->err->format_message)(info, errors->message);
  std::longjmp(errors->jump, 1);
}

/// Corrupt-data warnings: libjpeg goes on (filling what is missing), as it does for OpenCV.
void IgnoreJpegMessage(j_common_ptr /*info*/) {}

/// The libjpeg state of one read, released in every outcome.
struct JpegSession {
  std::FILE* file = nullptr;
  jpeg_decompress_struct info{};
  JpegErrors errors;
  bool created = false;

  JpegSession() = default;
  JpegSession(const JpegSession&) = delete;
  JpegSession& operator=(const JpegSession&) = delete;
  ~JpegSession() {
    if (created) jpeg_destroy_decompress(&info);
    if (file != nullptr) std::fclose(file);
  }
};

bool HasExif(const jpeg_decompress_struct& info) {
  for (jpeg_saved_marker_ptr m = info.marker_list; m != nullptr; m = m->next) {
    if (m->marker == JPEG_APP0 + 1 && m->data_length >= 6 &&
        std::memcmp(m->data, "Exif\0\0", 6) == 0) {
      return true;
    }
  }
  return false;
}

bool ReadHeader(JpegSession* s) {
  if (setjmp(s->errors.jump) != 0) return false;
  jpeg_create_decompress(&s->info);
  s->created = true;
  jpeg_stdio_src(&s->info, s->file);
  jpeg_save_markers(&s->info, JPEG_APP0 + 1, 0xffff);
  jpeg_read_header(&s->info, TRUE);
  jpeg_calc_output_dimensions(&s->info);
  return true;
}

/// Reads every scanline into `data` (row stride `step`), `channels` 1 (grey) or 3 (BGR).
bool ReadRows(JpegSession* s, int channels, JDIMENSION width, JDIMENSION height, JSAMPLE* data,
              std::size_t step) {
  if (setjmp(s->errors.jump) != 0) return false;
  s->info.out_color_space = channels == 1 ? JCS_GRAYSCALE : JCS_EXT_BGR;
  s->info.out_color_components = channels;
  jpeg_start_decompress(&s->info);
  // The scanlines must be what the caller allocated (the header's size, `channels`).
  if (s->info.output_components != channels || s->info.output_width != width ||
      s->info.output_height != height) {
    std::snprintf(s->errors.message, sizeof(s->errors.message), "unexpected scanline layout");
    return false;
  }
  while (s->info.output_scanline < s->info.output_height) {
    JSAMPROW row = data + static_cast<std::size_t>(s->info.output_scanline) * step;
    jpeg_read_scanlines(&s->info, &row, 1);
  }
  return true;
}

/// OpenCV ignores errors after the last scanline (trailing data); so does this.
void Finish(JpegSession* s) {
  if (setjmp(s->errors.jump) != 0) return;
  jpeg_finish_decompress(&s->info);
}

bool NeedsOpenCv(const jpeg_decompress_struct& info) {
  const bool missing_huffman =
      info.ac_huff_tbl_ptrs[0] == nullptr && info.ac_huff_tbl_ptrs[1] == nullptr &&
      info.dc_huff_tbl_ptrs[0] == nullptr && info.dc_huff_tbl_ptrs[1] == nullptr;
  return info.num_components == 4 || HasExif(info) || missing_huffman;
}

}  // namespace

DecodeResult DecodeJpeg(const std::string& path, ImageReadMode mode, long long max_pixels,
                        cv::Size* size_only) {
  DecodeResult result;
  JpegSession s;
  s.info.err = jpeg_std_error(&s.errors.base);
  s.errors.base.error_exit = OnJpegError;
  s.errors.base.output_message = IgnoreJpegMessage;
  s.file = std::fopen(path.c_str(), "rb");
  if (s.file == nullptr) {
    result.message = "cannot open";
    return result;
  }
  if (!ReadHeader(&s)) {
    result.message = std::string("corrupt JPEG: ") + s.errors.message;
    return result;
  }
  const long long width = s.info.output_width, height = s.info.output_height;
  if (width == 0 || height == 0 || width * height > max_pixels || width > (1 << 20) ||
      height > (1 << 20)) {
    result.message = "JPEG of " + std::to_string(width) + "x" + std::to_string(height) +
                     " pixels: empty or too large";
    return result;
  }
  if (NeedsOpenCv(s.info)) {  // also for the size: an Exif orientation may swap it
    result.status = DecodeStatus::kNotHandled;
    return result;
  }
  if (size_only != nullptr) {
    *size_only = cv::Size(static_cast<int>(width), static_cast<int>(height));
    result.status = DecodeStatus::kOk;
    return result;
  }
  const int channels = mode == ImageReadMode::kUnchanged && s.info.num_components > 1 ? 3 : 1;
  cv::Mat pixels(static_cast<int>(height), static_cast<int>(width), CV_8UC(channels));
  if (!ReadRows(&s, channels, static_cast<JDIMENSION>(width), static_cast<JDIMENSION>(height),
                pixels.data, pixels.step)) {
    result.message = std::string("corrupt JPEG: ") + s.errors.message;
    return result;
  }
  Finish(&s);
  result.status = DecodeStatus::kOk;
  result.pixels = std::move(pixels);
  return result;
}

}  // namespace parallax::codecs
