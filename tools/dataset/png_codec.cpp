// PNG through libpng, with the transformations OpenCV 4's PNG decoder asks of libpng for the
// same read mode (so the same pixels): 16 bits stripped for 8-bit output, alpha stripped,
// palettes and 1/2/4-bit grey expanded, colour to grey with weights 0.299/0.587 (libpng's
// fixed-point conversion), BGR order for colour output.
//
// libpng reports errors by longjmp. The functions that call setjmp hold only trivially
// destructible locals and allocate nothing, so a jump skips no destructor.

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "tools/dataset/image_codecs.hpp"
#include "tools/dataset/png_direct.hpp"

namespace parallax::codecs {
namespace {

struct PngHeader {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int bit_depth = 0;
  int color_type = 0;
  bool has_transparency = false;
};

/// The libpng state of one read or write, released in every outcome.
struct PngSession {
  std::FILE* file = nullptr;
  png_structp png = nullptr;
  png_infop info = nullptr;
  bool writing = false;
  char message[200] = "unknown libpng error";

  PngSession() = default;
  PngSession(const PngSession&) = delete;
  PngSession& operator=(const PngSession&) = delete;
  ~PngSession() {
    if (png != nullptr) {
      if (writing) {
        png_destroy_write_struct(&png, info != nullptr ? &info : nullptr);
      } else {
        png_destroy_read_struct(&png, info != nullptr ? &info : nullptr, nullptr);
      }
    }
    if (file != nullptr) std::fclose(file);
  }
};

void OnPngError(png_structp png, png_const_charp message) {
  auto* session = static_cast<PngSession*>(png_get_error_ptr(png));
  std::snprintf(session->message, sizeof(session->message), "%s", message);
  png_longjmp(png, 1);
}

void IgnorePngWarning(png_structp /*png*/, png_const_charp /*message*/) {}

bool ReadHeader(PngSession* s, PngHeader* header) {
  if (setjmp(png_jmpbuf(s->png)) != 0) return false;
  png_init_io(s->png, s->file);
  png_read_info(s->png, s->info);
  png_get_IHDR(s->png, s->info, &header->width, &header->height, &header->bit_depth,
               &header->color_type, nullptr, nullptr, nullptr);
  png_bytep trans = nullptr;
  int num_trans = 0;
  png_color_16p trans_values = nullptr;
  if (header->color_type == PNG_COLOR_TYPE_RGB || header->color_type == PNG_COLOR_TYPE_PALETTE) {
    png_get_tRNS(s->png, s->info, &trans, &num_trans, &trans_values);
  }
  header->has_transparency = num_trans > 0;
  return true;
}

/// OpenCV's channel count for IMREAD_UNCHANGED.
int UnchangedChannels(const PngHeader& h) {
  switch (h.color_type) {
    case PNG_COLOR_TYPE_RGB:
    case PNG_COLOR_TYPE_PALETTE:
      return h.has_transparency ? 4 : 3;
    case PNG_COLOR_TYPE_GRAY_ALPHA:
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return 4;
    default:
      return 1;
  }
}

/// Sets the transformations for `channels` output channels of `eight_bit` depth and reads
/// every row (all interlace passes) into `data` with row stride `step`.
bool ReadRows(PngSession* s, const PngHeader* h, int channels, bool eight_bit, png_bytep data,
              std::size_t step) {
  if (setjmp(png_jmpbuf(s->png)) != 0) return false;
  if (eight_bit && h->bit_depth == 16) {
    png_set_strip_16(s->png);
  } else {
    png_set_swap(s->png);  // 16-bit samples are big-endian in the file
  }
  if (channels < 4) {
    png_set_strip_alpha(s->png);
  } else {
    png_set_tRNS_to_alpha(s->png);
  }
  if (h->color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(s->png);
  if ((h->color_type & PNG_COLOR_MASK_COLOR) == 0 && h->bit_depth < 8) {
    png_set_expand_gray_1_2_4_to_8(s->png);
  }
  if ((h->color_type & PNG_COLOR_MASK_COLOR) != 0 && channels > 1) {
    png_set_bgr(s->png);
  } else if (channels > 1) {
    png_set_gray_to_rgb(s->png);
  } else {
    png_set_rgb_to_gray(s->png, 1, 0.299, 0.587);
  }
  const int passes = png_set_interlace_handling(s->png);
  png_read_update_info(s->png, s->info);
  // The rows must be what the caller allocated, whatever the file's combination of chunks.
  const std::size_t sample_bytes = eight_bit ? 1 : 2;
  if (png_get_rowbytes(s->png, s->info) !=
      h->width * static_cast<std::size_t>(channels) * sample_bytes) {
    std::snprintf(s->message, sizeof(s->message), "unexpected row layout");
    return false;
  }
  for (int pass = 0; pass < passes; ++pass) {
    for (png_uint_32 y = 0; y < h->height; ++y) png_read_row(s->png, data + y * step, nullptr);
  }
  png_read_end(s->png, nullptr);
  return true;
}

/// The file's bytes in a buffer reused by the thread (empty when it cannot be read: libpng
/// then reports why).
const std::vector<std::uint8_t>& ReadWholeFile(const std::string& path) {
  thread_local std::vector<std::uint8_t> bytes;
  bytes.clear();
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return bytes;
  if (std::fseek(file, 0, SEEK_END) == 0) {
    const long size = std::ftell(file);
    if (size > 0 && std::fseek(file, 0, SEEK_SET) == 0) {
      bytes.resize(static_cast<std::size_t>(size));
      bytes.resize(std::fread(bytes.data(), 1, bytes.size(), file));
    }
  }
  std::fclose(file);
  return bytes;
}

bool WriteRows(PngSession* s, const cv::Mat* image, int level) {
  if (setjmp(png_jmpbuf(s->png)) != 0) return false;
  png_init_io(s->png, s->file);
  png_set_compression_level(s->png, level);
  const int bit_depth = image->depth() == CV_16U ? 16 : 8;
  const int color_type = image->channels() == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_GRAY;
  png_set_IHDR(s->png, s->info, static_cast<png_uint_32>(image->cols),
               static_cast<png_uint_32>(image->rows), bit_depth, color_type, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(s->png, s->info);
  if (bit_depth == 16) png_set_swap(s->png);
  if (color_type == PNG_COLOR_TYPE_RGB) png_set_bgr(s->png);
  for (int y = 0; y < image->rows; ++y) png_write_row(s->png, image->ptr<png_byte>(y));
  png_write_end(s->png, s->info);
  return true;
}

}  // namespace

DecodeResult DecodePng(const std::string& path, ImageReadMode mode, long long max_pixels,
                       cv::Size* size_only, PngDecoders decoders) {
  DecodeResult result;
  if (size_only == nullptr && mode == ImageReadMode::kGrey8 &&
      decoders == PngDecoders::kDirectFirst) {
    // A sequence's frames: the direct decoder, when the file is one it handles.
    const std::vector<std::uint8_t>& bytes = ReadWholeFile(path);
    if (auto grey = DecodeCommonPng(bytes.data(), bytes.size(), max_pixels)) {
      result.status = DecodeStatus::kOk;
      result.pixels = std::move(*grey);
      return result;
    }
  }
  PngSession s;
  s.file = std::fopen(path.c_str(), "rb");
  if (s.file == nullptr) {
    result.message = "cannot open";
    return result;
  }
  s.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &s, OnPngError, IgnorePngWarning);
  if (s.png != nullptr) s.info = png_create_info_struct(s.png);
  if (s.info == nullptr) {
    result.message = "out of memory";
    return result;
  }
  PngHeader header;
  if (!ReadHeader(&s, &header)) {
    result.message = std::string("corrupt PNG: ") + s.message;
    return result;
  }
  const long long num_pixels = static_cast<long long>(header.width) * header.height;
  if (header.width == 0 || header.height == 0 || num_pixels > max_pixels ||
      header.width > (1U << 20) || header.height > (1U << 20)) {
    result.message = "PNG of " + std::to_string(header.width) + "x" +
                     std::to_string(header.height) + " pixels: empty or too large";
    return result;
  }
  if (size_only != nullptr) {
    *size_only = cv::Size(static_cast<int>(header.width), static_cast<int>(header.height));
    result.status = DecodeStatus::kOk;
    return result;
  }
  const bool unchanged = mode == ImageReadMode::kUnchanged;
  const int channels = unchanged ? UnchangedChannels(header) : 1;
  const bool eight_bit = !unchanged || header.bit_depth <= 8;
  cv::Mat pixels(static_cast<int>(header.height), static_cast<int>(header.width),
                 CV_MAKETYPE(eight_bit ? CV_8U : CV_16U, channels));
  if (!ReadRows(&s, &header, channels, eight_bit, pixels.data, pixels.step)) {
    result.message = std::string("corrupt PNG: ") + s.message;
    return result;
  }
  result.status = DecodeStatus::kOk;
  result.pixels = std::move(pixels);
  return result;
}

bool EncodePng(const std::string& path, const cv::Mat& image, int level, std::string* message) {
  if (image.empty() || (image.depth() != CV_8U && image.depth() != CV_16U) ||
      (image.channels() != 1 && image.channels() != 3)) {
    *message = "not an 8/16-bit one- or three-channel image";
    return false;
  }
  PngSession s;
  s.writing = true;
  s.file = std::fopen(path.c_str(), "wb");
  if (s.file == nullptr) {
    *message = std::string("cannot open for writing: ") + std::strerror(errno);
    return false;
  }
  s.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &s, OnPngError, IgnorePngWarning);
  if (s.png != nullptr) s.info = png_create_info_struct(s.png);
  if (s.info == nullptr) {
    *message = "out of memory";
    return false;
  }
  if (!WriteRows(&s, &image, level)) {
    *message = s.message;
    return false;
  }
  if (std::fflush(s.file) != 0) {
    *message = std::string("write failed: ") + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace parallax::codecs
